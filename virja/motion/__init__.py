"""Motion: quaternions (w x y z), skeletons and FK, BVH, the clip library, blending, BandPose.

Public entry points: :class:`virja.motion.band.BandAnimator`,
:class:`virja.motion.pose.BandPose`, :func:`virja.motion.export.performance_to_bvh`,
:func:`virja.motion.bench.pose_ms`.  See docs/motion.md.
"""

from virja import quat as quat  # moved to virja.quat (the renderer uses it too); old imports work
