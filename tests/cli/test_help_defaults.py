"""Every "(default X)" in a subcommand's help is argparse's actual default."""

from __future__ import annotations

import argparse
import re
from collections.abc import Iterator

import pytest

from virja.cli.main import COMMANDS, build_parser


def stated_defaults() -> Iterator[tuple[str, str, object, str]]:
    for name in COMMANDS:
        parser = build_parser(name)
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        for action in sub.choices[name]._actions:
            m = re.search(r"\(default:? ([^,;)]+)\)", action.help or "")
            if m and action.default is not None and not isinstance(action.default, bool):
                yield name, action.option_strings[-1], action.default, m.group(1).strip()


CASES = list(stated_defaults())


def test_there_are_defaults_to_check() -> None:
    assert len(CASES) >= 20


@pytest.mark.parametrize(("command", "option", "default", "stated"), CASES)
def test_help_states_the_real_default(
    command: str, option: str, default: object, stated: str
) -> None:
    word = stated.split()[0]
    if isinstance(default, int | float):
        assert float(word) == float(default), f"{command} {option}: help says {stated!r}"
    else:
        assert word == str(default), f"{command} {option}: help says {stated!r}"
