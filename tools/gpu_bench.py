"""Render speed at several frame sizes, for a machine with a GPU (or without one).

Prints, for each size: the GL draw time of one frame (scenes built beforehand),
render fps of the whole band with pose and scene building, with and without
read-back; then the offline real-time factor of `virja render` of the demo to
.mp4 (with sound when fluidsynth is installed, else --no-audio, and it says so).

    python tools/gpu_bench.py                       # 1280x720 1920x1080 3840x2160
    python tools/gpu_bench.py --sizes 1280x720 --json

The figures of docs/performance.md's GPU section come from this command.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys


def _size(text: str) -> tuple[int, int]:
    w, _, h = text.partition("x")
    return int(w), int(h)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", nargs="+", default=["1280x720", "1920x1080", "3840x2160"])
    ap.add_argument("--seconds", type=float, default=4.0, help="per fps figure")
    ap.add_argument("--offline-sizes", nargs="*", default=["1280x720", "1920x1080"])
    ap.add_argument("--end", type=float, default=None, help="render the demo only to here")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()

    from virja.bench import gl_draw_ms, offline_realtime_factor, render_fps

    out: dict[str, object] = {}
    for text in args.sizes:
        size = _size(text)
        fps, gl = render_fps(seconds=args.seconds, size=size)
        fps_rb, _ = render_fps(seconds=args.seconds, size=size, readback=True)
        draw = gl_draw_ms(size=size)
        out["gl_renderer"] = gl
        out[text] = {"gl_draw_ms": draw, "render_fps": fps, "render_fps_readback": fps_rb}
        if not args.json:
            print(
                f"{text:>10}: GL draw {draw:6.2f} ms/frame, render {fps:6.1f} fps, "
                f"with read-back {fps_rb:6.1f} fps  ({gl})",
                flush=True,
            )
    for text in args.offline_sizes:
        sound = shutil.which("fluidsynth") is not None
        rtf, music = offline_realtime_factor(args.end, size=text, audio=sound)
        out[f"offline_{text}"] = {"realtime_factor": rtf, "music_s": music, "sound": sound}
        if not args.json:
            print(
                f"offline render of {music:.1f} s of the demo at {text}, 30 fps, .mp4 "
                f"{'with sound' if sound else 'without sound (no fluidsynth)'}: "
                f"{rtf:.2f}x real time",
                flush=True,
            )
    if args.json:
        print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
