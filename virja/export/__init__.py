"""Exports of a whole performance for other tools, without GL: glTF 2.0, BVH, MusicXML 4.0.

``export_file(input_path, *, gltf=None, bvh=None, musicxml=None, fps=30, start_s=None,
end_s=None, config=None) -> list[Path]`` does a whole export of one input
(:mod:`virja.export.driver`); the formats are in :mod:`virja.export.gltf` and
:mod:`virja.export.musicxml` (BVH: :mod:`virja.motion.export`).
"""

from virja.export.driver import Export, export_file, export_performance

__all__ = ["Export", "export_file", "export_performance"]
