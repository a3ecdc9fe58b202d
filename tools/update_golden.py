"""Re-render the golden images the renderer's tests compare against.

Run after an intended change to the look (geometry, clips, shaders, scene):

    .venv/bin/python tools/update_golden.py

then open the PNGs in tests/data/golden/ and look at them before committing.
"""

from __future__ import annotations

from pathlib import Path

from virja.cli.main import main

REPO = Path(__file__).resolve().parent.parent
GOLDEN = REPO / "tests" / "data" / "golden"
DEMO = REPO / "virja" / "demo" / "blues.mid"

# name -> (time in the demo, camera); small frames keep the files and the test cheap
FRAMES = {
    "demo_front_6.900": (6.9, "front"),
    "demo_drums_6.932": (6.932, "drums"),
    "demo_bass_3.640": (3.64, "bass"),
}
SIZE = "192x108"


def render(name: str, out: Path) -> int:
    t, camera = FRAMES[name]
    return main(
        ["render", str(DEMO), "--out", str(out), "--at", str(t), "--camera", camera, "--size", SIZE]
    )


if __name__ == "__main__":
    GOLDEN.mkdir(parents=True, exist_ok=True)
    for frame in FRAMES:
        if render(frame, GOLDEN / f"{frame}.png") != 0:
            raise SystemExit(1)
