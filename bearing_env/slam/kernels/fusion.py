"""Fusing one movement's region of a landmark into a map: the strict intersection and
the relaxed fusion's window and bases (``csrc/slam/fusion.cpp``).

The strict intersection clips a landmark's region by the movement's new region; an
empty result is an inconsistency, handled by the map's policy. The relaxed fusion keeps
the last movements' regions in a window and reports, per landmark, the hull of the
points in all of them but at most ``q`` (the smallest ``q`` up to ``max_outliers`` that
leaves a non-empty set); a movement left out for every landmark is rejected, and regions
older than the window fold into the bases. :func:`relaxed_region` is that rule on one
landmark's window (``bearing_env.slam.geometry.relaxed_intersection``).
"""

from __future__ import annotations

from bearing_env._core import relaxed_region

__all__ = ["relaxed_region"]
