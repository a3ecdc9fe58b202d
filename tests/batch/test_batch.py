"""virja batch: jobs, the manifest, atomic outputs, resume, the process pool and Ray."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.batch.crashy import run_or_die
from virja.batch import OutputKind, Status, discover, make_jobs
from virja.batch.executors import LocalPool
from virja.batch.jobs import Job, parse_kinds
from virja.batch.manifest import JobResult, place_outputs, read_manifest
from virja.batch.run import run_batch
from virja.batch.work import BatchSettings
from virja.cli.main import main
from virja.errors import ConfigError, InputFileError
from virja.plan.config import load_plan_config
from virja.routing import RoutingConfig


def _find_gmd() -> Path:
    """The Groove MIDI Dataset: $VIRJA_GMD, else shared/data/gmd beside the checkout
    (CI clones the repository next to shared/; a worktree may sit deeper)."""
    if os.environ.get("VIRJA_GMD"):
        return Path(os.environ["VIRJA_GMD"])
    for parent in Path(__file__).resolve().parents:
        if (parent / "shared" / "data" / "gmd").is_dir():
            return parent / "shared" / "data" / "gmd"
    return Path("shared/data/gmd")


GMD = _find_gmd()
TAKES = [
    "drummer1/eval_session/1_funk-groove1_138_beat_4-4.mid",
    "drummer1/eval_session/8_rock-groove8_65_beat_4-4.mid",
    "drummer7/session1/34_hiphop_100_fill_4-4.mid",
]


def gmd(rel: str) -> Path:
    path = GMD / rel
    if not path.is_file():
        pytest.skip(f"the Groove MIDI Dataset is not beside the checkout ({path})")
    return path


@pytest.fixture
def corpus(tmp_path: Path) -> Path:
    """Three GMD takes in a tree of folders, a corrupt MIDI file, and files to pass over."""
    root = tmp_path / "in"
    for rel in TAKES:
        dest = root / rel
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(gmd(rel), dest)
    (root / "broken").mkdir()
    (root / "broken" / "corrupt.mid").write_bytes(b"MThd\x00\x00\x00\x06\x00\x01\x00")
    (root / "notes.txt").write_text("not an input")
    (root / ".hidden").mkdir()
    (root / ".hidden" / "x.mid").write_bytes(b"")
    return root


def settings() -> BatchSettings:
    return BatchSettings(plan=load_plan_config(None), routing=RoutingConfig())


def virja_plan_json(path: Path, capsys: pytest.CaptureFixture[str]) -> str:
    assert main(["plan", "--json", str(path)]) == 0
    return capsys.readouterr().out


def test_discover_walks_sorted_and_passes_over_hidden_and_other_files(corpus: Path) -> None:
    assert discover(corpus) == sorted([*TAKES, "broken/corrupt.mid"])


def test_discover_refuses_a_missing_or_empty_folder(tmp_path: Path) -> None:
    with pytest.raises(InputFileError, match="not a folder"):
        discover(tmp_path / "nope")
    with pytest.raises(InputFileError, match="no MIDI files"):
        discover(tmp_path)


def test_outputs_mirror_the_input_path() -> None:
    job = Job("a/b/take.mid", (OutputKind.PLAN, OutputKind.BVH))
    assert job.all_outputs() == ("a/b/take.plan.jsonl", "a/b/take_drums.bvh", "a/b/take_bass.bvh")


def test_export_names_are_checked() -> None:
    assert parse_kinds("plan, BVH") == (OutputKind.PLAN, OutputKind.BVH)
    with pytest.raises(ConfigError, match="unknown output 'pdf'"):
        parse_kinds("plan,pdf")
    with pytest.raises(ConfigError, match="named twice"):
        parse_kinds("plan,plan")


def test_colliding_outputs_are_refused_before_any_work() -> None:
    with pytest.raises(ConfigError, match="would both write x/a.plan.jsonl"):
        make_jobs(["x/a.mid", "x/a.midi"], (OutputKind.PLAN,))


def test_a_failed_write_leaves_no_output(tmp_path: Path) -> None:
    out = tmp_path / "out"
    (out / "d").mkdir(parents=True)
    (out / "d" / "blocked").write_text("a file where a folder must go")
    result = JobResult(
        "d/x.mid", Status.OK, 1.0, files={"d/x.plan.jsonl": b"{}\n", "d/blocked/x.bvh": b"HIER"}
    )
    place_outputs(result, out)
    assert result.status is Status.ERROR and "cannot write" in (result.error or "")
    assert result.outputs == [] and not (out / "d" / "x.plan.jsonl").exists()


def test_batch_on_the_process_pool_writes_outputs_and_a_manifest(
    corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    code = main(["batch", str(corpus), "--out", str(out), "--export", "plan,bvh", "--workers", "2"])
    assert code == 1  # one input failed
    printed = capsys.readouterr()
    assert "3 ok, 1 failed, 0 skipped" in printed.out
    assert "corrupt.mid" in printed.out
    rows = read_manifest(out / "manifest.jsonl")
    assert [r["input"] for r in rows] == [
        str(corpus / r) for r in sorted([*TAKES, "broken/corrupt.mid"])
    ]
    for row in rows:
        assert set(row) >= {"input", "status", "outputs", "seconds"}
        assert isinstance(row["seconds"], float) and row["seconds"] >= 0
    bad = rows[0]
    assert bad["status"] == "error" and bad["outputs"] == [] and "corrupt.mid" in bad["error"]
    assert str(corpus) not in bad["error"] or "broken/corrupt.mid" in bad["error"]
    for row in rows[1:]:
        assert row["status"] == "ok" and "error" not in row
        assert [Path(p).name.split(".")[0].rsplit("_", 1)[-1] for p in row["outputs"][1:]] == [
            "drums",
            "bass",
        ]
        for p in row["outputs"]:
            assert Path(p).is_file() and Path(p).stat().st_size > 0
            assert Path(p).stat().st_mode & 0o644 == 0o644  # ordinary files, not mkstemp's 0600
    # the plan is exactly `virja plan --json`'s
    take = corpus / TAKES[0]
    expected = virja_plan_json(take, capsys)
    plan_out = out / TAKES[0].replace(".mid", ".plan.jsonl")
    assert plan_out.read_text() == expected and expected.count("\n") > 100
    # BVH our own reader accepts, frames at --fps
    from virja.motion.bvh import read_bvh

    bvh = read_bvh(out / TAKES[0].replace(".mid", "_drums.bvh"))
    assert bvh.frame_time_s == pytest.approx(1 / 30)
    assert not (out / ".virja-partial").exists()


def test_gltf_and_musicxml_come_from_one_export_pass(
    corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import xml.etree.ElementTree as ET

    shutil.rmtree(corpus / "drummer1")
    shutil.rmtree(corpus / "broken")
    out = tmp_path / "out"
    code = main(["batch", str(corpus), "--out", str(out), "--export", "gltf,musicxml,bvh"])
    assert code == 0, capsys.readouterr()
    (row,) = read_manifest(out / "manifest.jsonl")
    stem = out / TAKES[2].removesuffix(".mid")
    assert row["outputs"] == [
        f"{stem}.glb",
        f"{stem}.musicxml",
        f"{stem}_drums.bvh",
        f"{stem}_bass.bvh",
    ]
    assert Path(f"{stem}.glb").read_bytes()[:4] == b"glTF"
    root = ET.parse(f"{stem}.musicxml").getroot()
    assert root.tag == "score-partwise" and root.find("part") is not None


def test_skip_existing_skips_done_inputs_and_retries_failed_ones(
    corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    args = ["batch", str(corpus), "--out", str(out), "--export", "plan", "--workers", "1"]
    main(args)
    capsys.readouterr()
    done = out / TAKES[1].replace(".mid", ".plan.jsonl")
    done.unlink()
    assert main([*args, "--skip-existing"]) == 1
    rows = {Path(r["input"]).name: r for r in read_manifest(out / "manifest.jsonl")}
    assert rows[Path(TAKES[1]).name]["status"] == "ok" and done.is_file()
    assert rows[Path(TAKES[0]).name]["status"] == "skipped"
    assert rows[Path(TAKES[0]).name]["outputs"] == [
        str(out / TAKES[0].replace(".mid", ".plan.jsonl"))
    ]
    assert rows["corrupt.mid"]["status"] == "error"


def _workers_of(token: str) -> list[int]:
    """Live processes carrying the environment marker ``token`` (an orphaned pool
    worker's parent becomes 1, so they are found by what they inherited)."""
    found = []
    for proc_dir in Path("/proc").iterdir():
        if not proc_dir.name.isdigit():
            continue
        try:
            env = (proc_dir / "environ").read_bytes()
            state = (proc_dir / "stat").read_text().split()[2]
        except OSError:
            continue
        if f"VIRJA_BATCH_TEST={token}".encode() in env and state != "Z":
            found.append(int(proc_dir.name))
    return found


def test_a_killed_batch_resumes_where_it_stopped(corpus: Path, tmp_path: Path) -> None:
    """SIGKILL halfway, then --skip-existing: nothing half-written is taken as done."""
    shutil.rmtree(corpus / "broken")
    for i in range(5):  # more inputs, so the kill lands mid-batch
        shutil.copy(corpus / TAKES[0], corpus / f"copy{i}.mid")
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "virja", "batch", str(corpus), "--out", str(out)]
    cmd += ["--export", "plan,bvh", "--workers", "1"]
    token = f"{os.getpid()}-{time.monotonic_ns()}"
    marker = os.environ | {"VIRJA_BATCH_TEST": token}
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=marker)
    manifest = out / "manifest.jsonl"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        if manifest.is_file() and manifest.read_text().count("\n") >= 2:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=10)
    # its workers die with it (PR_SET_PDEATHSIG): none is left behind, stuck on a pipe
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and _workers_of(token):
        time.sleep(0.05)
    assert not _workers_of(token)
    first = read_manifest(manifest)
    assert 2 <= len(first) < 8, "the kill should land halfway"
    # what a kill in the middle of writing leaves behind: a temporary file, never a final name
    partial = out / ".virja-partial"
    partial.mkdir(exist_ok=True)
    (partial / "copy4_drums.bvh.abc").write_bytes(b"HIER")
    resumed = subprocess.run([*cmd, "--skip-existing"], capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    rows = read_manifest(manifest)
    assert len(rows) == 8 and len({r["input"] for r in rows}) == 8
    statuses = [r["status"] for r in rows]
    assert statuses.count("skipped") >= len(first) and statuses.count("error") == 0
    assert not partial.exists()
    for row in rows:
        for p in row["outputs"]:
            assert Path(p).stat().st_size > 0


def test_a_dead_worker_fails_only_its_own_input(corpus: Path, tmp_path: Path) -> None:
    (corpus / "broken" / "corrupt.mid").unlink()
    shutil.copy(corpus / TAKES[0], corpus / "broken" / "crash.mid")
    jobs = make_jobs(discover(corpus), (OutputKind.PLAN,))
    pool = LocalPool(2, job_fn=run_or_die)
    try:
        summary = run_batch(corpus, tmp_path / "out", jobs, settings(), pool)
    finally:
        pool.close()
    assert summary.counts[Status.OK] == 3 and summary.counts[Status.ERROR] == 1
    assert summary.errors[0][0].endswith("crash.mid") and "worker died" in summary.errors[0][1]


def test_batch_on_a_local_ray_cluster_gives_the_same_outputs(
    corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("ray", reason="the Ray extra is installed by tools/setup.sh")
    shutil.rmtree(corpus / "drummer7")
    code = main(
        [
            "batch",
            str(corpus),
            "--out",
            str(tmp_path / "ray"),
            "--export",
            "plan",
            "--ray",
            "--workers",
            "2",
        ]
    )
    assert code == 1
    assert "on Ray (local" in capsys.readouterr().out
    rows = read_manifest(tmp_path / "ray" / "manifest.jsonl")
    assert [r["status"] for r in rows] == ["error", "ok", "ok"]
    for rel in TAKES[:2]:
        got = (tmp_path / "ray" / rel.replace(".mid", ".plan.jsonl")).read_text()
        assert got == virja_plan_json(corpus / rel, capsys)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--export", "pdf"], "unknown output 'pdf'"),
        (["--workers", "0"], "--workers must be 1-1024"),
        (["--workers", "99999999999999999999"], "--workers must be 1-1024"),
        (["--fps", "0"], "--fps must be in"),
        (["--size", "big"], "size must look like"),
        (["--config", "/nonexistent.toml"], "nonexistent.toml"),
    ],
)
def test_bad_options_are_one_line_errors_before_any_work(
    corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    out = tmp_path / "out"
    assert main(["batch", str(corpus), "--out", str(out), *extra]) == 1
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err and err.count("\n") == 1
    assert not (out / "manifest.jsonl").exists()


def test_an_unwritable_out_folder_is_a_clear_error(
    corpus: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["batch", str(corpus), "--out", str(blocker / "sub")]) == 1
    assert "cannot write there" in capsys.readouterr().err


def test_manifest_lines_are_json_objects(corpus: Path, tmp_path: Path) -> None:
    jobs = make_jobs(discover(corpus)[:1], (OutputKind.PLAN,))
    pool = LocalPool(1)
    try:
        run_batch(corpus, tmp_path / "out", jobs, settings(), pool)
    finally:
        pool.close()
    lines = (tmp_path / "out" / "manifest.jsonl").read_text().splitlines()
    assert len(lines) == 1 and json.loads(lines[0])["status"] == "error"
    assert os.listdir(tmp_path / "out") == ["manifest.jsonl"]
