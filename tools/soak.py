"""Soak the daemon: `virja serve --headless` under a mixed RMCP load for N minutes.

A benchmark/harness, not a test.  It starts `virja serve --headless --record
--plan-log` on 127.0.0.1 and sends it, over loopback only:

- valid notes at a dense tempo: 16th notes at ``--bpm`` (200) from a bass
  sender (id 1, channel 1, program 32) and a drums sender (id 2, channel 10:
  hi-hat every 16th, kick on 1 and 3, snare on 2 and 4), each note-on and
  note-off its own datagram, plus BEATs from id 3; every datagram is sent one
  beat before its time stamp, which is session time (Unix µs);
- invalid datagrams (``--invalid-per-s``): random bytes, truncations of valid
  datagrams, bad magic, bad version, bad flags, a non-zero reserved byte;
- duplicates (``--dup-per-s``): the exact bytes of a valid datagram again;
- a jump of the drums sender's clock: for ``--jump-beats`` beats in the middle
  of the run its time stamps are ``--jump-s`` (5 s) ahead, then back.

It samples the daemon's resident memory (/proc/PID/status VmRSS) every
``--sample-s``, stops the daemon with SIGTERM after the load and a drain, and
reports RSS over time (first, max, last, slope in KB/min), drops by reason
from the daemon's summary against what was sent, sent vs planned notes, and
whether the ``--record`` pcap holds every datagram sent (payload multisets).
Exit status 1 when a check fails (daemon crashed or hung, datagrams missing
from the recording, drops not matching what was sent, notes unaccounted for,
RSS slope after warm-up above ``--max-rss-slope-kb-min``).

    .venv/bin/python tools/soak.py --minutes 1
    .venv/bin/python tools/soak.py --minutes 0.5 --keep /tmp/soak   # keep pcap, logs
"""

from __future__ import annotations

import argparse
import os
import random
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from virja.clock import SessionClock
from virja.rmcp import wire
from virja.rmcp.errors import RmcpError
from virja.rmcp.pcap import read_capture

BASS, DRUMS, BEATS, JUNK = 1, 2, 3, 0  # sender ids (JUNK: the socket of invalid datagrams)
BASS_CH, DRUM_CH = 0, 9
BASS_PROGRAM = 32  # GM Acoustic Bass: the router sends the channel to the bassist
HIHAT, KICK, SNARE = 42, 36, 38
STEPS_PER_BEAT = 4  # 16th notes
BEATS_PER_BAR = 4
START_DELAY_S = 0.5  # first time stamp after the daemon is up
DRAIN_S = 1.0  # after the last send, before SIGTERM
EXIT_TIMEOUT_S = 30.0
LISTEN_TIMEOUT_S = 60.0
MAX_SAMPLES = 100_000  # bound on RSS samples whatever --sample-s says


@dataclass(frozen=True, slots=True)
class Send:
    """One datagram to send ``at_us`` (session time) from the socket of ``sock``."""

    at_us: int
    sock: int
    payload: bytes
    category: str  # "valid", "duplicate", or "invalid"
    note_ons: int = 0


@dataclass
class Load:
    """The whole schedule, in send order, and what it should produce."""

    sends: list[Send]
    note_ons: int = 0
    expected_drops: Counter[str] = field(default_factory=Counter)
    categories: Counter[str] = field(default_factory=Counter)


def expected_reason(payload: bytes) -> str | None:
    """The parse reason the receiver counts for ``payload`` (None when it is valid)."""
    try:
        wire.Datagram.parse(payload)
    except RmcpError as exc:
        return exc.reason
    return None


def _invalid(rng: random.Random, valid: bytes) -> tuple[str, bytes]:
    """One invalid datagram, derived from ``valid`` or random; returns (variant, bytes)."""
    variant = rng.choice(
        ("random", "truncated", "bad_magic", "bad_version", "bad_flags", "reserved")
    )
    if variant == "random":
        return variant, rng.randbytes(rng.randrange(0, 1301))
    if variant == "truncated":
        return variant, valid[: rng.randrange(0, len(valid))]
    b = bytearray(valid)
    if variant == "bad_magic":
        b[rng.randrange(4)] ^= rng.randrange(1, 256)
    elif variant == "bad_version":
        b[4] = rng.choice([v for v in range(256) if v != wire.VERSION])
    elif variant == "bad_flags":
        b[6] |= rng.randrange(1, 64) << 2
    else:
        b[7] = rng.randrange(1, 256)
    return variant, bytes(b)


def build_load(
    *,
    start_us: int,
    duration_s: float,
    bpm: float,
    invalid_per_s: float,
    dup_per_s: float,
    jump_s: float,
    jump_beats: int,
    seed: int,
) -> Load:
    """The schedule of a soak (pure): time stamps from ``start_us``, sends one beat earlier."""
    rng = random.Random(seed)
    beat_us = round(60e6 / bpm)
    step_us = beat_us // STEPS_PER_BEAT
    n_beats = max(1, int(duration_s * 1e6 // beat_us))
    jump_from = n_beats // 2
    seqs = Counter[int]()
    load = Load([])
    valid: list[Send] = []

    def add(sender: int, time_us: int, *msgs: bytes) -> None:
        d = wire.midi(sender, seqs[sender] % (1 << 32), time_us, *msgs)
        seqs[sender] += 1
        ons = sum(1 for m in msgs if m[0] & 0xF0 == 0x90 and m[2] > 0)
        valid.append(Send(time_us - beat_us, sender, bytes(d), "valid", ons))

    add(BASS, start_us, bytes((0xC0 | BASS_CH, BASS_PROGRAM)))
    bass_note = 40  # E2
    for b in range(n_beats):
        beat_time = start_us + beat_us + b * beat_us  # the first beat one beat after start
        d = wire.beat(
            BEATS,
            seqs[BEATS],
            beat_time,
            bar=b // BEATS_PER_BAR,
            beat=b % BEATS_PER_BAR + 1,
            beats_per_bar=BEATS_PER_BAR,
            level=2 if b % BEATS_PER_BAR == 0 else (1 if b % 2 == 0 else 0),
            tempo_us=beat_us,
        )
        seqs[BEATS] += 1
        valid.append(Send(beat_time - beat_us, BEATS, bytes(d), "valid"))
        drum_shift = round(jump_s * 1e6) if jump_from <= b < jump_from + jump_beats else 0
        for s in range(STEPS_PER_BEAT):
            t = beat_time + s * step_us
            bass_note = min(55, max(28, bass_note + rng.choice((-2, -1, 1, 2, 3, -3))))
            add(BASS, t, bytes((0x90 | BASS_CH, bass_note, rng.randrange(70, 110))))
            add(BASS, t + step_us * 3 // 4, bytes((0x80 | BASS_CH, bass_note, 0)))
            hits = [HIHAT]
            if s == 0:
                hits.append(KICK if b % 2 == 0 else SNARE)
            td = t + drum_shift
            add(DRUMS, td, *(bytes((0x90 | DRUM_CH, n, rng.randrange(60, 120))) for n in hits))
            add(DRUMS, td + step_us // 2, *(bytes((0x80 | DRUM_CH, n, 0)) for n in hits))
    end_us = start_us + n_beats * beat_us
    sends = list(valid)
    for _ in range(round(invalid_per_s * duration_s)):
        variant, payload = _invalid(rng, rng.choice(valid).payload)
        reason = expected_reason(payload)
        if reason is None:  # a random mutation that happens to be valid: not an invalid one
            continue
        load.expected_drops[reason] += 1
        load.categories[f"invalid_{variant}"] += 1
        sends.append(Send(rng.randrange(start_us, end_us), JUNK, payload, "invalid"))
    for _ in range(round(dup_per_s * duration_s)):
        orig = rng.choice(valid)
        sends.append(Send(orig.at_us + 50_000, orig.sock, orig.payload, "duplicate"))
        load.expected_drops["duplicate"] += 1
        load.categories["duplicate"] += 1
    load.categories["valid"] = len(valid)
    load.note_ons = sum(s.note_ons for s in valid)
    load.sends = sorted(sends, key=lambda s: s.at_us)
    return load


# -- the daemon's summary -------------------------------------------------------


def _pairs(text: str) -> Counter[str]:
    """``"bad_magic 3, duplicate 5"`` -> Counter; ``"none"`` -> empty."""
    out: Counter[str] = Counter()
    for m in re.finditer(r"([A-Za-z_][\w]*) (\d+)", text):
        out[m.group(1)] += int(m.group(2))
    return out


@dataclass
class Summary:
    received: int = -1
    accepted: int = -1
    by_kind: Counter[str] = field(default_factory=Counter)
    dropped: Counter[str] = field(default_factory=Counter)
    planned: int = -1
    late: int = -1
    not_the_bands: int = -1
    scheduler: Counter[str] = field(default_factory=Counter)
    found: bool = False


def parse_summary(stdout: str) -> Summary:
    """The figures of the summary `virja serve` prints on exit."""
    s = Summary()
    for raw in stdout.splitlines():
        line = raw.strip()
        if m := re.match(r"datagrams: (\d+) received, (\d+) accepted", line):
            s.received, s.accepted, s.found = int(m.group(1)), int(m.group(2)), True
        elif line.startswith("by kind: "):
            s.by_kind = _pairs(line[len("by kind: ") :])
        elif line.startswith("dropped: "):
            s.dropped = _pairs(line[len("dropped: ") :])
        elif m := re.match(
            r"notes: (\d+) planned, (\d+) arrived late.*?, (\d+) not the band", line
        ):
            s.planned, s.late, s.not_the_bands = (int(g) for g in m.groups())
        elif line.startswith("scheduler: "):
            s.scheduler = _pairs(line[len("scheduler: ") :])
    return s


# -- memory -------------------------------------------------------------------------


def read_rss_kb(pid: int) -> int | None:
    """VmRSS of a process in KB (None once it is gone)."""
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return None
    m = re.search(r"^VmRSS:\s+(\d+) kB", text, re.M)
    return int(m.group(1)) if m else None


def slope_kb_per_min(samples: list[tuple[float, int]]) -> float:
    """Least-squares slope of (seconds, KB) samples, in KB per minute (0 with < 2)."""
    if len(samples) < 2:
        return 0.0
    n = len(samples)
    mt = sum(t for t, _ in samples) / n
    mv = sum(v for _, v in samples) / n
    den = sum((t - mt) ** 2 for t, _ in samples)
    if den == 0:
        return 0.0
    return sum((t - mt) * (v - mv) for t, v in samples) / den * 60.0


# -- running ----------------------------------------------------------------------


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


def wait_listening(proc: subprocess.Popen[bytes], out: Path, timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if "listening on" in out.read_text(errors="replace"):
            return True
        if proc.poll() is not None:
            return False
        time.sleep(0.05)
    return False


@dataclass
class RunResult:
    sent: Counter[bytes] = field(default_factory=Counter)
    sent_n: int = 0
    rss: list[tuple[float, int]] = field(default_factory=list)
    max_lag_ms: float = 0.0
    lags_over_10ms: int = 0
    died_early: bool = False


def drive(
    load: Load,
    pid: int,
    proc: subprocess.Popen[bytes],
    port: int,
    clock: SessionClock,
    sample_s: float,
) -> RunResult:
    """Send the schedule on time, sampling RSS; stops early if the daemon dies."""
    res = RunResult()
    socks = {
        k: socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for k in (JUNK, BASS, DRUMS, BEATS)
    }
    try:
        for s in socks.values():
            s.bind(("127.0.0.1", 0))
        t0 = time.monotonic()
        next_sample = t0
        for item in load.sends:
            while True:
                now_us = clock.now_us()
                if time.monotonic() >= next_sample and len(res.rss) < MAX_SAMPLES:
                    rss = read_rss_kb(pid)
                    if rss is None or proc.poll() is not None:
                        res.died_early = True
                        return res
                    res.rss.append((time.monotonic() - t0, rss))
                    next_sample += sample_s
                wait_us = item.at_us - now_us
                if wait_us <= 0:
                    break
                time.sleep(min(wait_us / 1e6, max(0.0, next_sample - time.monotonic()), 0.05))
            lag_ms = (clock.now_us() - item.at_us) / 1000
            res.max_lag_ms = max(res.max_lag_ms, lag_ms)
            res.lags_over_10ms += lag_ms > 10
            socks[item.sock].sendto(item.payload, ("127.0.0.1", port))
            res.sent[item.payload] += 1
            res.sent_n += 1
        end = time.monotonic() + DRAIN_S
        while time.monotonic() < end:
            time.sleep(0.05)
        rss = read_rss_kb(pid)
        if rss is not None:
            res.rss.append((time.monotonic() - t0, rss))
    finally:
        for s in socks.values():
            s.close()
    return res


def stop(proc: subprocess.Popen[bytes]) -> tuple[int | None, bool]:
    """SIGTERM, wait; SIGKILL if it hangs.  Returns (exit status, hung)."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
    try:
        return proc.wait(timeout=EXIT_TIMEOUT_S), False
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        return None, True


def report_rss(rss: list[tuple[float, int]], warmup_s: float) -> tuple[float, float]:
    """Print RSS over time; returns (slope over all samples, slope after warm-up)."""
    if not rss:
        print("RSS: no samples")
        return 0.0, 0.0
    values = [v for _, v in rss]
    slope_all = slope_kb_per_min(rss)
    after = [(t, v) for t, v in rss if t >= warmup_s]
    slope_after = slope_kb_per_min(after)
    print(
        f"RSS (KB): first {values[0]}, max {max(values)}, last {values[-1]}, "
        f"slope {slope_all:+.1f} KB/min over {len(rss)} samples, "
        f"{slope_after:+.1f} KB/min after {warmup_s:.0f} s warm-up ({len(after)} samples)"
    )
    step = max(1, len(rss) // 12)
    shown = rss[::step] + ([rss[-1]] if (len(rss) - 1) % step else [])
    print("  RSS over time: " + ", ".join(f"{t:.0f}s {v}" for t, v in shown))
    return slope_all, slope_after


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument(
        "--minutes", type=float, default=10.0, help="length of the load (default 10; 0.5 ok)"
    )
    p.add_argument("--bpm", type=float, default=200.0, help="tempo of the 16th notes (default 200)")
    p.add_argument(
        "--invalid-per-s", type=float, default=5.0, help="invalid datagrams per second (5)"
    )
    p.add_argument(
        "--dup-per-s", type=float, default=2.0, help="duplicated datagrams per second (2)"
    )
    p.add_argument("--jump-s", type=float, default=5.0, help="drums clock jump, seconds (5)")
    p.add_argument("--jump-beats", type=int, default=8, help="beats the jump lasts (8)")
    p.add_argument("--sample-s", type=float, default=2.0, help="RSS sampling period (2 s)")
    p.add_argument(
        "--max-rss-slope-kb-min",
        type=float,
        default=1024.0,
        help="fail above this RSS growth after warm-up (default 1024 KB/min)",
    )
    p.add_argument(
        "--port", type=int, default=0, help="UDP port for the daemon (default: a free one)"
    )
    p.add_argument("--seed", type=int, default=1, help="random seed of the load (1)")
    p.add_argument("--keep", metavar="DIR", help="keep the pcap, plan log and daemon output in DIR")
    args = p.parse_args(argv)
    if not 0 < args.minutes <= 24 * 60:
        p.error("--minutes must be > 0 and at most 1440")
    if args.sample_s <= 0 or args.bpm <= 0 or args.invalid_per_s < 0 or args.dup_per_s < 0:
        p.error("--sample-s and --bpm must be > 0, rates >= 0")
    if args.keep:
        workdir = Path(args.keep)
        workdir.mkdir(parents=True, exist_ok=True)
        return soak(args, workdir)
    with tempfile.TemporaryDirectory(prefix="virja-soak-") as tmp:
        return soak(args, Path(tmp))


def soak(args: argparse.Namespace, workdir: Path) -> int:
    duration_s = args.minutes * 60.0
    port = args.port or free_udp_port()
    pcap, plan_log = workdir / "soak.pcap", workdir / "plan.jsonl"
    out_path, err_path = workdir / "serve.out", workdir / "serve.err"
    backstop_s = START_DELAY_S + duration_s + 60.0  # the daemon stops itself even if we die
    cmd = [
        sys.executable, "-m", "virja", "serve", "--headless", "--quiet",
        "--listen", f"127.0.0.1:{port}", "--record", str(pcap), "--plan-log", str(plan_log),
        "--duration", f"{backstop_s:.1f}",
    ]  # fmt: skip
    print("daemon: " + " ".join(cmd[1:]))
    with out_path.open("wb") as out, err_path.open("wb") as err:
        proc = subprocess.Popen(
            cmd, stdout=out, stderr=err, env=dict(os.environ, PYTHONUNBUFFERED="1")
        )
        try:
            if not wait_listening(proc, out_path, LISTEN_TIMEOUT_S):
                stop(proc)
                print("FAIL: the daemon did not start listening")
                print(err_path.read_text(errors="replace")[-2000:])
                return 1
            clock = SessionClock()
            start_us = clock.now_us() + round(START_DELAY_S * 1e6)
            load = build_load(
                start_us=start_us,
                duration_s=duration_s,
                bpm=args.bpm,
                invalid_per_s=args.invalid_per_s,
                dup_per_s=args.dup_per_s,
                jump_s=args.jump_s,
                jump_beats=args.jump_beats,
                seed=args.seed,
            )
            print(
                f"load: {len(load.sends)} datagrams over {duration_s:.0f} s to 127.0.0.1:{port}: "
                + ", ".join(f"{k} {v}" for k, v in sorted(load.categories.items()))
            )
            res = drive(load, proc.pid, proc, port, clock, args.sample_s)
        finally:
            status, hung = stop(proc)
    return check(
        args, load, res, status, hung, out_path, err_path, pcap, plan_log, port, duration_s
    )


def check(
    args: argparse.Namespace,
    load: Load,
    res: RunResult,
    status: int | None,
    hung: bool,
    out_path: Path,
    err_path: Path,
    pcap: Path,
    plan_log: Path,
    port: int,
    duration_s: float,
) -> int:
    failures: list[str] = []
    stdout = out_path.read_text(errors="replace")
    summary = parse_summary(stdout)
    print(
        f"sent: {res.sent_n} datagrams of {len(load.sends)} scheduled; send lag max "
        f"{res.max_lag_ms:.1f} ms, {res.lags_over_10ms} sends more than 10 ms late"
    )
    if res.died_early:
        failures.append("the daemon died during the load")
    if hung:
        failures.append(f"the daemon did not exit within {EXIT_TIMEOUT_S:.0f} s of SIGTERM")
    elif status != 0:
        failures.append(f"the daemon exited with status {status}")
    if not summary.found:
        failures.append("no summary in the daemon's output")
        tail = err_path.read_text(errors="replace")[-1500:]
        if tail:
            print("daemon stderr (tail):\n" + tail)

    warmup_s = min(30.0, duration_s / 2)  # the daemon keeps 20 s of motion (KEEP_MOTION_S)
    _, slope_after = report_rss(res.rss, warmup_s)
    if slope_after > args.max_rss_slope_kb_min:
        failures.append(
            f"RSS grows {slope_after:.0f} KB/min after warm-up (limit {args.max_rss_slope_kb_min:.0f})"
        )

    if summary.found:
        print(
            f"daemon: {summary.received} received, {summary.accepted} accepted; by kind: "
            + ", ".join(f"{k} {v}" for k, v in sorted(summary.by_kind.items()))
        )
        if summary.received != res.sent_n:
            failures.append(f"daemon received {summary.received} of {res.sent_n} datagrams sent")
        print("drops (reason: daemon / expected from what was sent):")
        expected = load.expected_drops if not res.died_early else Counter[str]()
        for reason in sorted(set(summary.dropped) | set(expected)):
            got, want = summary.dropped.get(reason, 0), expected.get(reason, 0)
            mark = "" if got == want else "   <-- differs"
            print(f"  {reason}: {got} / {want}{mark}")
            if got != want and not res.died_early:
                failures.append(f"drops {reason}: daemon {got}, expected {want}")
        sched_dropped = summary.scheduler.get("dropped", 0)
        recv_note_drops = summary.dropped.get("too_late", 0)
        print(
            f"notes: {load.note_ons} note-ons sent, {summary.planned} planned, "
            f"{sched_dropped} dropped by the scheduler ("
            + ", ".join(f"{k} {v}" for k, v in sorted(summary.scheduler.items()) if k != "dropped")
            + f"), {recv_note_drops} too late, {summary.late} arrived late, "
            f"{summary.not_the_bands} not the band's"
        )
        accounted = summary.planned + sched_dropped + recv_note_drops + summary.not_the_bands
        if not res.died_early and accounted != load.note_ons:
            failures.append(
                f"notes unaccounted: sent {load.note_ons}, planned + dropped + too late + "
                f"not the band's = {accounted}"
            )
        if plan_log.exists():
            lines = sum(1 for ln in plan_log.read_text().splitlines() if ln.strip())
            print(f"plan log: {lines} lines")
            if lines != summary.planned:
                failures.append(
                    f"plan log has {lines} lines, summary says {summary.planned} planned"
                )

    try:
        cap = read_capture(pcap, port=port, allow_empty=True)
        recorded = Counter(d.payload for d in cap.datagrams)
        missing = res.sent - recorded
        extra = recorded - res.sent
        print(
            f"recording: {len(cap.datagrams)} datagrams in {pcap.name}, "
            f"{sum(missing.values())} sent but missing, {sum(extra.values())} not sent"
            + (f", warnings: {cap.warnings}" if cap.warnings else "")
        )
        if missing or extra:
            failures.append(
                f"recording differs: {sum(missing.values())} missing, {sum(extra.values())} extra"
            )
    except Exception as exc:  # the harness reports any failure to read the recording
        failures.append(f"recording unreadable: {exc}")

    if failures:
        print("FAIL:\n  " + "\n  ".join(failures))
        return 1
    print("OK: every check passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
