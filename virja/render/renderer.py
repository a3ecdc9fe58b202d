"""The GL side: instanced primitives drawn with one program, a few calls a frame.

:class:`DrawList` collects instances per mesh kind (transforms and colours as
numpy arrays); :class:`Renderer` uploads them and draws them into whatever
framebuffer the host gives (a window's screen or an offscreen target).  It
knows nothing of notes or skeletons: ``virja.render.scene`` turns a
``BandPose`` into a DrawList.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import moderngl
import numpy as np
from numpy.typing import ArrayLike, NDArray

from virja.render.camera import Camera
from virja.render.meshes import MESHES, pack_instances
from virja.render.shaders import load_program

F64 = NDArray[np.float64]

BACKGROUND = (0.055, 0.06, 0.085)
# the shader's lights (also sent to the browser viewer, virja.web): directions towards
# the key and fill lights, the stage spot's position
LIGHTS: dict[str, tuple[float, float, float]] = {
    "u_key_dir": (0.35, 0.85, 0.55),
    "u_fill_dir": (-0.6, 0.3, 0.4),
    "u_spot_pos": (0.0, 3.2, 1.6),
}
_EMPTY = np.zeros((0, 20), dtype=np.float32)


@dataclass
class DrawList:
    """Instances to draw this frame, per mesh kind."""

    models: dict[str, list[F64]] = field(default_factory=dict)
    colors: dict[str, list[F64]] = field(default_factory=dict)
    _frozen: dict[str, NDArray[np.float32]] | None = None
    _rows: dict[str, NDArray[np.float32]] | None = None  # packed already (prepacked)

    @classmethod
    def prepacked(cls, rows: dict[str, NDArray[np.float32]]) -> DrawList:
        """A frame's instances already packed as (n, 20) float32 rows per kind (a slice
        of a chunk's table, :func:`virja.render.scene_batch.band_scenes`); unlike a
        frozen list it is not cached as a static layer."""
        return cls(_rows=rows)

    def add(self, kind: str, models: ArrayLike, color: ArrayLike) -> None:
        if self._frozen is not None:
            raise RuntimeError("this DrawList is frozen")
        if self._rows is not None:
            raise RuntimeError("this DrawList is prepacked")
        if kind not in MESHES:
            raise ValueError(f"unknown mesh kind {kind!r}; known: {sorted(MESHES)}")
        m = np.asarray(models, dtype=np.float64).reshape(-1, 4, 4)
        if len(m) == 0:
            return
        c = np.asarray(color, dtype=np.float64)
        c = np.broadcast_to(c.reshape(-1, 4) if c.size % 4 == 0 else c, (len(m), 4))
        self.models.setdefault(kind, []).append(m)
        self.colors.setdefault(kind, []).append(np.array(c))

    def packed(self, kind: str) -> NDArray[np.float32]:
        """(n, 20) float32 instance rows of ``kind``; cached once :meth:`freeze` is called."""
        if self._frozen is not None:
            return self._frozen.get(kind, _EMPTY)
        if self._rows is not None:
            return self._rows.get(kind, _EMPTY)
        if kind not in self.models:
            return _EMPTY
        return pack_instances(np.concatenate(self.models[kind]), np.concatenate(self.colors[kind]))

    @property
    def frozen(self) -> bool:
        return self._frozen is not None

    def freeze(self) -> DrawList:
        """Pack once and reuse (for the static stage and instruments)."""
        self._frozen = {k: self.packed(k) for k in self.models}
        return self

    def count(self) -> int:
        if self._rows is not None:
            return sum(len(r) for r in self._rows.values())
        return sum(sum(len(m) for m in ms) for ms in self.models.values())


class Renderer:
    """Draws DrawLists with the ``solid`` program."""

    def __init__(self, ctx: moderngl.Context, initial_instances: int = 512) -> None:
        self.ctx = ctx
        self.program = load_program(ctx, "solid")
        self._vbos: dict[str, moderngl.Buffer] = {}
        self._ebos: dict[str, moderngl.Buffer] = {}
        self._ibos: dict[str, moderngl.Buffer] = {}
        self._vaos: dict[str, moderngl.VertexArray] = {}
        self._capacity: dict[str, int] = {}
        self._layer: moderngl.Framebuffer | None = None
        self._layer_key: tuple[object, ...] | None = None
        for kind, make in MESHES.items():
            # Indexed: each distinct vertex is shaded once per instance (llvmpipe's
            # vertex cache), not once per triangle corner; the triangles are the same.
            # The sphere's pole triangles have two equal corners and cover no pixel:
            # they are left out (fewer triangles to set up, the same picture).
            verts, index = np.unique(make(), axis=0, return_inverse=True)
            tris = index.reshape(-1, 3)
            keep = (
                (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])
            )
            self._vbos[kind] = ctx.buffer(np.ascontiguousarray(verts, dtype=np.float32).tobytes())
            self._ebos[kind] = ctx.buffer(tris[keep].astype(np.uint32).tobytes())
            self._alloc(kind, initial_instances)

    def _alloc(self, kind: str, capacity: int) -> None:
        if kind in self._ibos:
            self._vaos[kind].release()
            self._ibos[kind].release()
        self._ibos[kind] = self.ctx.buffer(reserve=capacity * 20 * 4, dynamic=True)
        self._capacity[kind] = capacity
        self._vaos[kind] = self.ctx.vertex_array(
            self.program,
            [
                (self._vbos[kind], "3f 3f", "in_position", "in_normal"),
                (self._ibos[kind], "16f 4f/i", "in_model", "in_color"),
            ],
            index_buffer=self._ebos[kind],
            index_element_size=4,
        )

    def draw(
        self,
        draw_list: DrawList | Sequence[DrawList],
        camera: Camera,
        fbo: moderngl.Framebuffer,
    ) -> None:
        """Clear ``fbo`` and draw every instance of the list(s) as seen by ``camera``.

        When the first list is frozen (the static stage), it is drawn once into a
        cached colour + depth layer for this camera and size, and each frame starts
        from a copy of that layer: only what moves is drawn again.  On a CPU
        rasteriser this saves most of the frame (the floor and the instruments
        cover far more pixels than the players).
        """
        lists = [draw_list] if isinstance(draw_list, DrawList) else list(draw_list)
        self._begin(camera, fbo)
        if lists and lists[0].frozen:
            layer = self._static_layer(lists[0], camera, fbo)
            self.ctx.copy_framebuffer(fbo, layer)
            fbo.use()
            lists = lists[1:]
        else:
            fbo.clear(*BACKGROUND, 1.0, depth=1.0)
        self._draw_instances(lists)

    def _begin(self, camera: Camera, fbo: moderngl.Framebuffer) -> None:
        w, h = fbo.size
        fbo.use()
        self.ctx.viewport = (0, 0, w, h)
        self.ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        vp = camera.view_proj(w / max(h, 1))
        self._uniform("u_view_proj").write(vp.T.astype("f4").tobytes())
        self._set("u_eye", tuple(float(x) for x in camera.eye))
        self._set("u_key_dir", _unit(LIGHTS["u_key_dir"]))
        self._set("u_fill_dir", _unit(LIGHTS["u_fill_dir"]))
        self._set("u_spot_pos", LIGHTS["u_spot_pos"])
        self._set("u_fog_color", BACKGROUND)

    def _static_layer(
        self, static: DrawList, camera: Camera, fbo: moderngl.Framebuffer
    ) -> moderngl.Framebuffer:
        samples = fbo.samples
        key = (id(static), camera, fbo.size, samples)
        if self._layer is not None and self._layer_key == key:
            return self._layer
        if self._layer is None or (self._layer.size, self._layer.samples) != (fbo.size, samples):
            self._release_layer()
            self._layer = self.ctx.framebuffer(
                color_attachments=[self.ctx.renderbuffer(fbo.size, samples=samples)],
                depth_attachment=self.ctx.depth_renderbuffer(fbo.size, samples=samples),
            )
        self._layer.use()
        self._layer.clear(*BACKGROUND, 1.0, depth=1.0)
        self._draw_instances([static])
        self._layer_key = key
        fbo.use()
        return self._layer

    def _release_layer(self) -> None:
        if self._layer is None:
            return
        from virja.render.hosts import parking_framebuffer

        parking_framebuffer(self.ctx).use()  # never delete the bound framebuffer
        for att in self._layer.color_attachments:
            att.release()
        if self._layer.depth_attachment is not None:
            self._layer.depth_attachment.release()
        self._layer.release()
        self._layer = None

    def _draw_instances(self, lists: Sequence[DrawList]) -> None:
        for kind in MESHES:
            parts = [d.packed(kind) for d in lists]
            if not parts:
                continue
            data = parts[0] if len(parts) == 1 else np.concatenate(parts)
            n = len(data)
            if n == 0:
                continue
            if n > self._capacity[kind]:
                self._alloc(kind, max(n, 2 * self._capacity[kind]))
            self._ibos[kind].write(data.tobytes())
            self._vaos[kind].render(moderngl.TRIANGLES, instances=n)

    def _uniform(self, name: str) -> moderngl.Uniform:
        member = self.program[name]
        assert isinstance(member, moderngl.Uniform)
        return member

    def _set(self, name: str, value: tuple[float, ...]) -> None:
        if name in self.program:
            self._uniform(name).value = value

    def release(self) -> None:
        self._release_layer()
        for d in (self._vaos, self._ibos, self._vbos, self._ebos):
            for obj in d.values():
                obj.release()
        self.program.release()


def _unit(v: tuple[float, float, float]) -> tuple[float, float, float]:
    a = np.asarray(v, dtype=np.float64)
    a /= np.linalg.norm(a)
    return (float(a[0]), float(a[1]), float(a[2]))
