"""Extract beat times from audio (method B: low-band power increments).

Reads AUDIO (WAV, FLAC or anything libsndfile reads), mixes to mono,
resamples to 8 kHz and prints one beat time in seconds per line; with
--json one object {"beats": [...]}.  Times are note onsets; a steady pulse
gets the beats it did not sound filled in (periodicity stage, an extension;
--no-periodicity for the paper's rule alone).  See docs/dance.md.
"""

from __future__ import annotations

import argparse
import json
import sys

from virja.cli.common import finite_float
from virja.dance.audio import ANALYSIS_RATE_HZ, read_audio_8k
from virja.dance.beats import BeatParams, extract_beats


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("audio", metavar="AUDIO", help="audio file (WAV, FLAC, ...)")
    parser.add_argument(
        "--json", action="store_true", help='print {"beats": [...]} instead of lines'
    )
    parser.add_argument(
        "--k",
        type=finite_float,
        default=BeatParams().k_mad,
        help="threshold: local median + K robust deviations (default 1.5)",
    )
    parser.add_argument(
        "--no-periodicity",
        action="store_true",
        help="the paper's rule alone: no beats filled in on the beat period",
    )


def run(args: argparse.Namespace) -> int:
    x = read_audio_8k(args.audio)
    beats = [
        round(float(b), 4)
        for b in extract_beats(x, BeatParams(k_mad=args.k, periodicity=not args.no_periodicity))
    ]
    if args.json:
        print(json.dumps({"beats": beats}))
    else:
        for b in beats:
            print(f"{b:.4f}")
    if not beats:
        # silence, or no pulse in the 30-120 Hz band: say so, and fail, rather than print nothing
        print(
            f"virja beats: no beats found in {args.audio} ({len(x) / ANALYSIS_RATE_HZ:.1f} s): no onsets in "
            "the 30-120 Hz band stand out (silence, or music without a low pulse); "
            "a lower --k finds weaker ones",
            file=sys.stderr,
        )
        return 1
    return 0
