"""Options and set-up shared by the subcommands that play a performance."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from virja.config import load_config, section
from virja.errors import ConfigError
from virja.routing import RoutingConfig

if TYPE_CHECKING:
    from virja.pipeline import PerformanceSettings


def finite_float(text: str) -> float:
    """An argparse type: a finite number ("nan" and "inf" are refused, with a one-line error)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


SAMPLE_CHOICES = (1, 2, 4, 8)


def add_routing_arguments(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("routing (see docs/routing.md; flags win over --config)")
    g.add_argument(
        "--config", metavar="FILE.toml", help="configuration file ([routing], [plan], ...)"
    )
    g.add_argument(
        "--bass-channel",
        type=int,
        action="append",
        default=[],
        metavar="N",
        help="MIDI channel (1-16) the bassist plays; repeatable",
    )
    g.add_argument(
        "--drums-channel",
        type=int,
        action="append",
        default=[],
        metavar="N",
        help="MIDI channel (1-16) the drummer plays; repeatable",
    )
    g.add_argument(
        "--bass-track",
        action="append",
        default=[],
        metavar="NAME",
        help="track name the bassist plays; repeatable",
    )
    g.add_argument(
        "--ignore-track",
        action="append",
        default=[],
        metavar="NAME",
        help="track name nobody plays; repeatable",
    )


def routing_config(args: argparse.Namespace, doc: dict[str, Any] | None = None) -> RoutingConfig:
    doc = load_config(args.config) if doc is None else doc
    where = f"{args.config} [routing]" if getattr(args, "config", None) else "[routing]"
    base = RoutingConfig.from_dict(section(doc, "routing"), where)
    return base.with_overrides(
        bass_channels=args.bass_channel,
        drum_channels=args.drums_channel,
        bass_tracks=args.bass_track,
        ignore_tracks=args.ignore_track,
    )


def performance_settings(
    args: argparse.Namespace, doc: dict[str, Any] | None = None, *, immediate: bool = False
) -> PerformanceSettings:
    """The routing (flags over ``[routing]``) and the plan tables of ``--config``, parsed
    once for :func:`virja.pipeline.build_performance`; each error a one-line ConfigError."""
    from virja.pipeline import PerformanceSettings
    from virja.plan.config import load_plan_config

    routing = routing_config(args, doc)
    return PerformanceSettings(load_plan_config(args.config), routing, immediate=immediate)


def open_plan_log(path: str | None) -> IO[str] | None:
    """The plan log, opened now (before any work), or a one-line ConfigError."""
    if not path:
        return None
    p = Path(path)
    try:
        if p.parent and not p.parent.exists():
            p.parent.mkdir(parents=True, exist_ok=True)
        return p.open("w", encoding="utf-8", buffering=1)
    except OSError as exc:
        raise ConfigError(
            f"--plan-log {path}: cannot write it: {exc.strerror or exc}; give a writable path"
        ) from None


def check_writable(path: Path, flag: str) -> None:
    """Fail now, with a one-line ConfigError, if ``path`` cannot be written: before the
    work, not after it.  Makes the missing folders (as the writers would); a file that
    did not exist is removed again."""
    existed = path.exists()
    if path.is_dir():
        raise ConfigError(f"{flag} {path}: is a folder; give a file name")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("ab"):
            pass
    except OSError as exc:
        raise ConfigError(
            f"{flag} {path}: cannot write it: {exc.strerror or exc}; give a writable path"
        ) from None
    if not existed:
        path.unlink(missing_ok=True)


class ProgressBar:
    """A one-line progress bar on stderr (every 10 % when stderr is not a terminal)."""

    def __init__(self, label: str, stream: IO[str] | None = None) -> None:
        self.label = label
        self.stream = sys.stderr if stream is None else stream  # looked up now, not at import
        self.tty = self.stream.isatty()
        self._last_decile = -1

    def __call__(self, done: int, total: int, elapsed_s: float) -> None:
        frac = done / max(total, 1)
        rate = done / elapsed_s if elapsed_s > 0 else 0.0
        if self.tty:
            bar = "#" * int(frac * 30)
            self.stream.write(
                f"\r{self.label} [{bar:<30}] {frac:4.0%} {done}/{total} frames, {rate:5.1f} fps"
            )
            if done == total:
                self.stream.write("\n")
            self.stream.flush()
            return
        decile = int(frac * 10)
        if decile != self._last_decile:
            self._last_decile = decile
            self.stream.write(
                f"{self.label}: {frac:4.0%} ({done}/{total} frames, {rate:.1f} fps)\n"
            )
            self.stream.flush()
