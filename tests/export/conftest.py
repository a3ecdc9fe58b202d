"""Shared exports: the demo and a GMD take exported once per session (module-scoped work)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import DEMO_MID, REPO
from virja.export import Export, export_performance
from virja.midifile import read_midi
from virja.rmcp.pcap import PcapWriter
from virja.rmcp.sender import SendOptions, beats_of, schedule_pass
from virja.routing import Router, RoutingConfig

GMD = Path("/work/shared/data/gmd")
# a few Groove MIDI Dataset takes (CC BY 4.0, Magenta): a 6/8 rock beat and a 4/4 funk groove
GMD_TAKES = (
    "drummer6/session1/1_rock_70_beat_6-8.mid",
    "drummer1/eval_session/1_funk-groove1_138_beat_4-4.mid",
)
VALIDATOR = REPO / "tools" / "node" / "validate_gltf.js"


def gmd_take(name: str) -> Path:
    p = GMD / name
    if not p.is_file():
        pytest.skip(f"the Groove MIDI Dataset is not at {GMD}")
    return p


@pytest.fixture(scope="session")
def export_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("export")


@pytest.fixture(scope="session")
def demo_export(export_dir: Path) -> Export:
    out = export_dir / "demo"
    out.mkdir()
    return export_performance(
        DEMO_MID,
        gltf=out / "blues.glb",
        bvh=out / "blues.bvh",
        musicxml=out / "blues.musicxml",
        fps=30,
    )


def record_demo_pcap(path: Path) -> Path:
    """The demo as `virja send` would stream it (notes and beats a beat ahead), recorded."""
    session = read_midi(DEMO_MID)
    router = Router.for_session(session, RoutingConfig())
    beats = beats_of(session.tempo_map, session.duration_s, 4)
    t0 = 1_700_000_000_000_000
    sched, _ = schedule_pass(
        session.events, session.tempo_map, beats, SendOptions(), t0, route=router.route
    )
    with PcapWriter.open(path, local=("127.0.0.1", 50500)) as w:
        for s in sched:
            w.write(bytes(s.datagram), ("127.0.0.1", 4000), time_us=s.send_us)
    return path
