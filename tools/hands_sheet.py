"""Contact sheet of the drummer's hands between strokes (docs/images/drummer_hands_120_300.png).

Usage:  .venv/bin/python tools/hands_sheet.py SWING_120.mid SWING_300.mid [--out PNG]

Each input is rendered as `virja render FILE --out DIR --start 6 --end 6.49 --fps F
--size 960x540 --camera drums` (F = 8 for the first row, 10 for the second: frames
1/8 s and 1/10 s apart), each frame cropped to the drummer and halved; one row per
input.  The MMA files come from `tools/mma_jazz.py OUT --tempos 120,300`.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from virja.render.images import decode_png_rgb, write_png

CROP = (220, 70, 560, 360)  # x, y, width, height in a 960x540 frame: the drummer
FRAMES = 4


def row(midi: str, fps: float, start: float, work: Path) -> np.ndarray:
    out = work / f"{Path(midi).stem}_{fps:g}"
    end = start + (FRAMES - 0.5) / fps
    cmd = [sys.executable, "-m", "virja", "render", midi, "--out", f"{out}/", "--start",
           f"{start:g}", "--end", f"{end:g}", "--fps", f"{fps:g}", "--size", "960x540",
           "--camera", "drums"]  # fmt: skip
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    x, y, w, h = CROP
    tiles = []
    for png in sorted(out.glob("frame_*.png"))[:FRAMES]:
        rgb = decode_png_rgb(png.read_bytes())[y : y + h, x : x + w].astype(np.float64)
        half = rgb.reshape(h // 2, 2, w // 2, 2, 3).mean(axis=(1, 3))
        tiles.append(half.round().astype(np.uint8))
    return np.concatenate(tiles, axis=1)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("midi", nargs=2, help="the 120 bpm and the 300 bpm file")
    ap.add_argument("--out", default="docs/images/drummer_hands_120_300.png")
    ap.add_argument("--start", type=float, default=6.0)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        rows = [
            row(m, fps, args.start, Path(tmp)) for m, fps in zip(args.midi, (8, 10), strict=True)
        ]
    write_png(args.out, np.concatenate(rows, axis=0))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
