"""Load GLSL programs from shaders/.

A program is one ``NAME.glsl`` file with ``#if defined VERTEX_SHADER`` and
``#elif defined FRAGMENT_SHADER`` sections (moderngl-window's layout).  The
loader prepends ``#version``, the stage's define and ``#line 1`` so that driver
messages count the file's own lines, and a compile error names the file.
"""

from __future__ import annotations

import re
from pathlib import Path

import moderngl

from virja.errors import VirjaError
from virja.resources import shaders_dir

GLSL_VERSION = "#version 330 core"


class ShaderError(VirjaError, RuntimeError):
    """A shader failed to compile or link; the message names the file and line."""


def stage_source(text: str, stage: str) -> str:
    """The source for one stage ("VERTEX_SHADER" or "FRAGMENT_SHADER")."""
    return f"{GLSL_VERSION}\n#define {stage}\n#line 1\n{text}"


def _point_at_file(log: str, path: Path) -> str:
    # Mesa writes "0:12(5): error: ..."; other drivers "ERROR: 0:12: ...".
    return re.sub(r"\b0:(\d+)", lambda m: f"{path.name}:{m.group(1)}", log)


def load_program(ctx: moderngl.Context, name: str, folder: Path | None = None) -> moderngl.Program:
    """Compile and link ``NAME.glsl`` from the shaders folder."""
    path = (folder or shaders_dir()) / f"{name}.glsl"
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ShaderError(f"{path}: cannot read shader: {exc.strerror or exc}") from exc
    try:
        return ctx.program(
            vertex_shader=stage_source(text, "VERTEX_SHADER"),
            fragment_shader=stage_source(text, "FRAGMENT_SHADER"),
        )
    except moderngl.Error as exc:
        raise ShaderError(f"{path}: {_point_at_file(str(exc), path)}") from exc
