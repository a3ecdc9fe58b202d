"""Export a MIDI file or a pcap recording for other tools, without rendering.

The notes go through the same planning and animation as a performance (the
same reveal a beat ahead, router, scheduler and animator as `render`), but
nothing is drawn: the motion is sampled at exact 1/fps steps and written as

  --gltf OUT.glb|OUT.gltf  both figures and the instruments, animated (glTF 2.0;
                           .gltf writes OUT.bin beside it)
  --bvh OUT.bvh            one BVH per figure: OUT_drums.bvh and OUT_bass.bvh
  --musicxml OUT.musicxml  the bass (notation an octave above sounding + tablature,
                           each note's string and fret) and the drums (kit-map
                           noteheads, sticking R/L), tempo and time signature

Times are session seconds (a MIDI file's start is 0).  docs/export.md tells more.

examples:
  virja export virja/demo/blues.mid --gltf out/blues.glb --bvh out/blues.bvh --musicxml out/blues.musicxml
  virja export session.pcap --gltf out/session.gltf --fps 60 --start 10 --end 20
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from virja.cli.common import add_routing_arguments, finite_float, routing_config


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "input", metavar="INPUT", help="a MIDI file (.mid) or an RMCP recording (.pcap, .pcapng)"
    )
    p.add_argument("--gltf", metavar="OUT.glb", help="write glTF 2.0 (.glb binary or .gltf + .bin)")
    p.add_argument(
        "--bvh", metavar="OUT.bvh", help="write OUT_drums.bvh and OUT_bass.bvh (one per figure)"
    )
    p.add_argument("--musicxml", metavar="OUT.musicxml", help="write MusicXML 4.0 notation")
    p.add_argument(
        "--fps", type=finite_float, default=30.0, help="motion samples per second (default 30)"
    )
    p.add_argument(
        "--start",
        type=finite_float,
        metavar="SECONDS",
        help="first sample, seconds from the input's start (default: early enough for the first motion)",
    )
    p.add_argument(
        "--end",
        type=finite_float,
        metavar="SECONDS",
        help="last sample, seconds from the input's start (default: the last note plus 1.5 s)",
    )
    p.add_argument(
        "--lookahead-beats",
        type=finite_float,
        default=1.0,
        metavar="B",
        help="notes are known B beats ahead (default 1)",
    )
    add_routing_arguments(p)


def run(args: argparse.Namespace) -> int:
    from virja.errors import ConfigError
    from virja.export.driver import check_request, export_performance

    if args.lookahead_beats < 0:
        raise ConfigError("--lookahead-beats must be >= 0")
    started = time.perf_counter()

    def opt(value: str | None) -> Path | None:
        return Path(value) if value else None

    check_request(
        Path(args.input),
        opt(args.gltf),
        opt(args.bvh),
        opt(args.musicxml),
        args.fps,
        args.start,
        args.end,
    )
    result = export_performance(
        args.input,
        gltf=opt(args.gltf),
        bvh=opt(args.bvh),
        musicxml=opt(args.musicxml),
        fps=args.fps,
        start_s=args.start,
        end_s=args.end,
        config=args.config,
        routing=routing_config(args),
        lookahead_beats=args.lookahead_beats,
    )
    for line in result.report:
        print(line)
    for path in result.outputs:
        print(f"wrote {path}")
    took = time.perf_counter() - started
    span = result.t1_s - result.t0_s
    print(
        f"exported {span:.2f} s ({result.frames} samples at {args.fps:g} fps, "
        f"{len(result.planned)} notes planned) in {took:.2f} s, "
        f"{span / took if took > 0 else float('inf'):.0f}x real time"
    )
    return 0
