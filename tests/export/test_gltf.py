"""glTF export: the Khronos validator finds no errors; the node hierarchy reproduces the poses."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pygltflib
import pytest

from tests.export.conftest import GMD_TAKES, VALIDATOR, gmd_take
from virja import quat
from virja.export import Export, export_performance
from virja.geometry import GEOMETRY
from virja.motion import bass_lean
from virja.motion.band import BandAnimator
from virja.motion.skeleton import SKELETON


def validate(path: Path) -> dict[str, Any]:
    """The Khronos glTF Validator's report (npm gltf-validator, installed by tools/setup.sh)."""
    node = shutil.which("node")
    assert node, "node is needed for the glTF validator (tools/setup.sh)"
    assert (VALIDATOR.parent / "node_modules" / "gltf-validator").is_dir(), (
        "run tools/setup.sh: it installs gltf-validator into tools/node/node_modules"
    )
    out = subprocess.run(
        [node, str(VALIDATOR), str(path)], capture_output=True, text=True, timeout=120, check=True
    )
    report: dict[str, Any] = json.loads(out.stdout)
    return report


def _errors(report: dict[str, Any]) -> list[Any]:
    return [m for m in report["issues"]["messages"] if m["severity"] == 0]


def test_demo_glb_passes_the_khronos_validator(demo_export: Export) -> None:
    glb = next(p for p in demo_export.outputs if p.suffix == ".glb")
    report = validate(glb)
    assert report["issues"]["numErrors"] == 0, _errors(report)
    assert report["issues"]["numWarnings"] == 0, report["issues"]["messages"]
    assert report["info"]["animationCount"] == 1
    assert report["info"]["hasMorphTargets"]  # the strings


def _world(
    doc: pygltflib.GLTF2,
    node_i: int,
    parents: dict[int, int],
    rot: dict[int, Any],
    trans: dict[int, Any] | None = None,
) -> Any:
    """World matrix of a node with some rotations (and translations) replaced (an
    independent TRS composition)."""
    m = np.eye(4)
    chain = [node_i]
    while chain[-1] in parents:
        chain.append(parents[chain[-1]])
    for i in reversed(chain):
        n = doc.nodes[i]
        r = rot.get(i, n.rotation or [0, 0, 0, 1])
        t = np.eye(4)
        t[:3, 3] = (trans or {}).get(i, n.translation or [0, 0, 0])
        rm = np.eye(4)
        rm[:3, :3] = quat.to_matrix(np.array([r[3], r[0], r[1], r[2]]))
        s = np.diag([*(n.scale or [1, 1, 1]), 1.0])
        m = m @ t @ rm @ s
    return m


def _frames(doc: pygltflib.GLTF2, acc_i: int) -> Any:
    acc = doc.accessors[acc_i]
    view = doc.bufferViews[acc.bufferView]
    data = doc.binary_blob()[view.byteOffset : view.byteOffset + view.byteLength]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[acc.type]
    return np.frombuffer(data, dtype="<f4").reshape(acc.count, width)


def test_glb_node_hierarchy_reproduces_the_band_pose(demo_export: Export, tmp_path: Path) -> None:
    """pygltflib reads the file; composing its nodes' TRS with the animation's keyframe k
    puts every joint where BandAnimator.pose puts it at that time (float32 precision)."""
    glb = next(p for p in demo_export.outputs if p.suffix == ".glb")
    doc = pygltflib.GLTF2().load(str(glb))
    names = {n.name: i for i, n in enumerate(doc.nodes)}
    for fig in ("drums", "bass"):
        for joint in SKELETON.names:
            assert f"{fig}_{joint}" in names
    for piece in (
        "kit_ride",
        "kit_crash",
        "kit_crash2",
        "kit_crash2_boom",  # crash 2 hangs on a boom
        "kit_hihat",
        "kit_pedal_kick",
        "kit_pedal_hihat",
    ):
        assert piece in names
    assert "drums_stick_left" in names and "bass_string_G" in names
    parents = {c: i for i, n in enumerate(doc.nodes) for c in (n.children or [])}
    anims = {a.name: a for a in doc.animations}
    assert set(anims) == {"band"}
    times = _frames(doc, anims["band"].samplers[0].input)[:, 0]
    assert len(times) == demo_export.frames
    k = 200  # a frame in the second bar, both players busy
    t0 = doc.scenes[0].extras["virja"]["t0_s"]
    t = t0 + k / 30
    rot: dict[int, Any] = {}
    for a in anims.values():
        for ch in a.channels:
            if ch.target.path == "rotation":
                rot[ch.target.node] = _frames(doc, a.samplers[ch.sampler].output)[k]
    animator = _replan()
    pose = animator.pose(t)
    for fig, fp in (("drums", pose.drums), ("bass", pose.bass)):
        for j, joint in enumerate(SKELETON.names):
            world = _world(doc, names[f"{fig}_{joint}"], parents, rot)[:3, 3]
            assert np.allclose(world, fp.positions[j], atol=1e-4), (fig, joint)
    tip = _world(doc, names["drums_stick_right_tip"], parents, rot)[:3, 3]
    assert np.allclose(tip, pose.sticks[1, 1], atol=1e-4)
    # the bass leans with its player: its node at keyframe k is the pose's transform, and a
    # string's nut read from the file is where the leaning bass holds it
    trans = {
        ch.target.node: _frames(doc, a.samplers[ch.sampler].output)[k]
        for a in anims.values()
        for ch in a.channels
        if ch.target.path == "translation"
    }
    assert not np.allclose(pose.bass_transform, np.eye(4), atol=1e-4)
    inst = _world(doc, names["bass_instrument"], parents, rot, trans)
    assert np.allclose(inst, pose.bass_transform, atol=1e-4)
    nut = _world(doc, names["bass_string_G"], parents, rot, trans)[:3, 3]
    assert np.allclose(nut, bass_lean.apply(pose.bass_transform, GEOMETRY.bass.nut["G"]), atol=1e-4)


def _replan() -> BandAnimator:
    from tests.conftest import DEMO_MID
    from virja.input import load_performance_input
    from virja.plan.planner import OnlinePlanner
    from virja.routing import Router, RoutingConfig
    from virja.session import Performance, run_schedule

    src = load_performance_input(DEMO_MID, RoutingConfig())
    animator = BandAnimator()
    perf = Performance(
        router=Router.for_session(src.midi, RoutingConfig()),
        planner=OnlinePlanner(tempo=src.tempo),
        animator=animator,
    )
    run_schedule(perf, src.schedule)
    return animator


@pytest.mark.parametrize("take", GMD_TAKES)
def test_gmd_takes_export_valid_gltf_with_separate_buffer(take: str, tmp_path: Path) -> None:
    out = tmp_path / "take.gltf"
    written = export_performance(gmd_take(take), gltf=out, fps=24, end_s=8.0).outputs
    assert written == [out, tmp_path / "take.bin"]
    report = validate(out)
    assert report["issues"]["numErrors"] == 0, _errors(report)
    doc = json.loads(out.read_text())
    assert doc["buffers"][0]["uri"] == "take.bin"
    hihat = next(i for i, n in enumerate(doc["nodes"]) if n["name"] == "kit_hihat")
    paths = {
        c["target"]["path"]
        for a in doc["animations"]
        for c in a["channels"]
        if c["target"]["node"] == hihat
    }
    assert paths == {"rotation", "translation"}  # swings and rises with the pedal


def test_instrument_parts_move(demo_export: Export) -> None:
    """Pedals, cymbals, the hi-hat and the strings have channels whose values change."""
    glb = next(p for p in demo_export.outputs if p.suffix == ".glb")
    doc = pygltflib.GLTF2().load(str(glb))
    names = {i: n.name for i, n in enumerate(doc.nodes)}
    moving: dict[str, float] = {}
    for a in doc.animations:
        for ch in a.channels:
            values = _frames(doc, a.samplers[ch.sampler].output)
            spread = float(np.max(values.max(axis=0) - values.min(axis=0)))
            moving[f"{names[ch.target.node]}.{ch.target.path}"] = spread
    for key in (
        "kit_pedal_kick.rotation",
        "kit_pedal_hihat.rotation",
        "kit_crash.rotation",
        "kit_ride.rotation",
        "kit_hihat.translation",
        "bass_string_E.weights",
        "bass_string_G.weights",
        "bass_instrument.rotation",
        "bass_instrument.translation",
    ):
        assert moving[key] > 1e-3, key


def test_a_five_string_bass_exports_its_five_strings_all_vibrating(tmp_path: Path) -> None:
    """The glTF draws the strings of the planned tuning (the low B too), each with a
    vibration channel that moves, and no string the tuning lacks."""
    from tests.conftest import DEMO_MID

    config = tmp_path / "five.toml"
    config.write_text('[plan]\nbass_tuning = "five"\n')
    out = tmp_path / "five.glb"
    export_performance(DEMO_MID, gltf=out, config=config, end_s=6.0)
    doc = pygltflib.GLTF2().load(str(out))
    names = {i: n.name for i, n in enumerate(doc.nodes)}
    strings = sorted(n for n in names.values() if n and n.startswith("bass_string_"))
    assert strings == sorted(f"bass_string_{s}" for s in "BEADG")
    vibrating = {
        names[ch.target.node]
        for a in doc.animations
        for ch in a.channels
        if ch.target.path == "weights" and names[ch.target.node].startswith("bass_string_")
    }
    assert vibrating == set(strings)
    assert not _errors(validate(out))


def _positions(doc: pygltflib.GLTF2, mesh: int) -> np.ndarray:
    """The POSITION vertices (k, 3) of a mesh's first primitive, from the GLB's blob."""
    acc = doc.accessors[doc.meshes[mesh].primitives[0].attributes.POSITION]
    view = doc.bufferViews[acc.bufferView]
    start = (view.byteOffset or 0) + (acc.byteOffset or 0)
    blob = doc.binary_blob()
    return np.frombuffer(blob[start : start + acc.count * 12], dtype=np.float32).reshape(-1, 3)


@pytest.mark.parametrize("tuning", ["four", "five", "six"])
def test_the_fingerboard_is_as_wide_as_the_tunings_strings(tmp_path: Path, tuning: str) -> None:
    """The exported fingerboard tapers with the tuning's strings: every string's ends on it
    (nut, and where the board ends) lie 5 mm or more inside its edges, in the bass's own
    frame (the board's parent leans it), and the file stays valid."""
    from tests.conftest import DEMO_MID
    from virja.fingerboard import fingerboard
    from virja.vocab import ALL_BASS_STRINGS

    config = tmp_path / f"{tuning}.toml"
    config.write_text(f'[plan]\nbass_tuning = "{tuning}"\n')
    out = tmp_path / f"{tuning}.glb"
    export_performance(DEMO_MID, gltf=out, config=config, end_s=2.0)
    doc = pygltflib.GLTF2().load(str(out))
    node = next(n for n in doc.nodes if n.name == "bass_fingerboard")
    assert node.translation is None and node.rotation is None and node.matrix is None
    strings = {"four": "EADG", "five": "BEADG", "six": "BEADGC"}[tuning]
    b = GEOMETRY.bass
    board = fingerboard(b, tuple(ALL_BASS_STRINGS))  # its frame (the same for every tuning)
    c = board.coords(_positions(doc, node.mesh).astype(np.float64))
    ends = (c[:, 0] < 1e-4, c[:, 0] > board.length - 1e-4)  # the nut's and the end's corners
    for s in strings:
        d = b.string_dir(s)
        nut = board.coords(b.nut[s])
        end = board.coords(b.nut[s] + d * (board.length - nut[0]) / (d @ board.along))
        for at, p in zip(ends, (nut, end), strict=True):
            lat = c[at, 1]
            assert lat.min() + 0.005 <= p[1] <= lat.max() - 0.005, (s, p, lat)
    assert not _errors(validate(out))
