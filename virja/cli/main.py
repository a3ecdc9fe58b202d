"""The ``virja`` command: one console script with subcommands.

Each subcommand lives in its own module ``virja.cli.cmd_<name>`` exposing
``add_arguments(parser)`` and ``run(args) -> int``; its module docstring is its
``--help`` text.  Modules are imported only when their subcommand runs, so a
missing optional backend (GL, MIDI ports) never breaks the others.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Sequence

from virja import __version__
from virja.errors import VirjaError

# name -> (module, one-line summary).  Order is the order of `virja --help`.
COMMANDS: dict[str, tuple[str, str]] = {
    "serve": ("virja.cli.cmd_serve", "receive RMCP/1 over UDP and draw the band live"),
    "send": (
        "virja.cli.cmd_send",
        "stream a MIDI file as RMCP/1, a stand-in performance generator",
    ),
    "plan": ("virja.cli.cmd_plan", "print the basic motions the scheduler picks for each note"),
    "render": ("virja.cli.cmd_render", "render a MIDI file or a recording to PNG frames or video"),
    "export": (
        "virja.cli.cmd_export",
        "export a performance as glTF, BVH and MusicXML (no rendering)",
    ),
    "replay": ("virja.cli.cmd_replay", "replay a pcap recording of RMCP traffic"),
    "jam": ("virja.cli.cmd_jam", "play a MIDI keyboard, the band plays what you play"),
    "batch": (
        "virja.cli.cmd_batch",
        "plan, export or render a whole folder of MIDI files (locally or on Ray)",
    ),
    "bench": ("virja.cli.cmd_bench", "measure speed and latency on this machine"),
    "motion-report": ("virja.cli.cmd_motion_report", "impact, contact and continuity metrics"),
    "beats": ("virja.cli.cmd_beats", "extract beat times from audio"),
    "teach": ("virja.cli.cmd_teach", "build a motion database from a capture and its music"),
    "dance": ("virja.cli.cmd_dance", "generate motion for new music from a database"),
}

USAGE = 2  # the exit status of `virja` with no command, as argparse exits on bad usage

DESCRIPTION = """\
virja: a virtual jazz band's bassist and drummer, drawn playing the notes you send.

Notes arrive over RMCP/1 (UDP), from MIDI files, from a MIDI keyboard, or from
pcap recordings; a cost-table scheduler picks the string and fret or the hand
for each, and every stroke and pluck lands on its sound."""

EPILOG = """\
examples:
  virja render virja/demo/blues.mid --out out/demo.mp4
  virja serve --headless --plan-log plan.jsonl      # and, in another shell:
  virja send virja/demo/blues.mid --to 127.0.0.1:50500

`virja COMMAND --help` tells more; docs/ in the source tree has the rest."""


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The argument parser; with ``only`` just that subcommand's module is imported."""
    parser = argparse.ArgumentParser(
        prog="virja",
        description=DESCRIPTION,
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"virja {__version__}")
    parser.add_argument(
        "-v", "--verbose", action="count", default=0, help="more logging (-vv debug)"
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (modname, summary) in COMMANDS.items():
        if only is not None and name != only:
            sub.add_parser(name, help=summary, add_help=False)
            continue
        module = importlib.import_module(modname)
        p = sub.add_parser(
            name,
            help=summary,
            description=module.__doc__,
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``virja``; returns the exit status."""
    args_list = list(sys.argv[1:] if argv is None else argv)
    only = next((a for a in args_list if a in COMMANDS), None)
    parser = build_parser(only)
    args = parser.parse_args(args_list)
    command = args.command or "virja"
    logging.basicConfig(
        level=logging.WARNING - 10 * min(args.verbose, 2),
        # plain one-liners like the errors; -v adds the time and the module
        format=(
            "%(asctime)s %(name)s %(levelname)s: %(message)s"
            if args.verbose
            else f"virja {command}: %(levelname)s: %(message)s".replace("virja virja", "virja")
        ),
        stream=sys.stderr,
    )
    logging.addLevelName(logging.WARNING, "warning" if not args.verbose else "WARNING")
    if args.command is None:
        parser.print_help()
        return USAGE
    try:
        result: int = args._run(args)
        return result
    except VirjaError as exc:
        print(f"virja {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"virja {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader went away (`virja plan ... | head`): stop quietly, as Unix tools do
        import os

        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    raise SystemExit(main())
