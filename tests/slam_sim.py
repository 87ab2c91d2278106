"""A tiny, independent simulator for the world-model tests (no bearing_env code).

Points are complex numbers (x + iy). A pose is a position and a heading (radians, CCW
from +x). A move is ``(heading, length)``: turn on the spot to ``heading``, read, go
straight over ``length``, read. Bearings are CCW from the direction of motion.

Noise is given in *normalised* form: arrays ``u`` in [-1, 1] that are scaled by a bound,
so the same draw can be replayed with different bounds (the paper's Fig. 11 setup).

Angles and unit vectors come from the C library's scalar ``atan2``, ``cos`` and ``sin``
(:func:`angle_of`, :func:`unit`), the functions the native core calls too, never from
NumPy's: NumPy picks its transcendental loops by the processor's features (AVX-512 or
not), and those round differently in the last bit on different machines, so seeded inputs
and the golden hashes taken over them would differ from machine to machine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * np.pi


def wrap(angle):
    """Wrap to [-pi, pi)."""
    return (np.asarray(angle, dtype=float) + np.pi) % TWO_PI - np.pi


def angle_of(z):
    """The argument of complex ``z`` (elementwise), by the C library's ``atan2``."""
    z = np.asarray(z, dtype=complex)
    return np.vectorize(math.atan2, otypes=[float])(z.imag, z.real)


def unit(angle):
    """``exp(i angle)`` (elementwise), by the C library's ``cos`` and ``sin``."""
    return np.vectorize(lambda a: complex(math.cos(a), math.sin(a)), otypes=[complex])(
        np.asarray(angle, dtype=float)
    )


def to_complex(xy) -> np.ndarray:
    arr = np.asarray(xy, dtype=float)
    return arr[..., 0] + 1j * arr[..., 1]


def to_xy(z) -> np.ndarray:
    z = np.asarray(z, dtype=complex)
    return np.stack([z.real, z.imag], axis=-1)


def true_bearings(landmarks: np.ndarray, position: complex, heading: float) -> np.ndarray:
    """Exact bearings of complex ``landmarks`` from ``position``, robot facing ``heading``."""
    return wrap(angle_of(landmarks - position) - heading)


def fl(points, l1: complex, l2: complex) -> np.ndarray:
    """Landmark-frame coordinates (complex) of world points (complex)."""
    return (np.asarray(points, dtype=complex) - l1) / (l2 - l1)


@dataclass
class Episode:
    """A world and a trajectory: everything needed to replay bearings."""

    landmarks: np.ndarray  # complex (n,)
    start: complex
    moves: list[tuple[float, float]]  # (heading, length)
    u_start: np.ndarray  # (n_moves, n) normalised noise at R1 of each move
    u_end: np.ndarray  # (n_moves, n) normalised noise at R2

    @property
    def n(self) -> int:
        return self.landmarks.shape[0]

    def poses(self) -> list[tuple[complex, complex, float]]:
        """(R1, R2, heading) of each move."""
        out = []
        pos = self.start
        for heading, length in self.moves:
            end = pos + length * unit(heading)
            out.append((pos, end, heading))
            pos = end
        return out

    def readings(self, noise_bound: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """(bearings_start, bearings_end) per move with noise ``u * noise_bound``."""
        out = []
        for m, (r1, r2, heading) in enumerate(self.poses()):
            b1 = wrap(true_bearings(self.landmarks, r1, heading) + noise_bound * self.u_start[m])
            b2 = wrap(true_bearings(self.landmarks, r2, heading) + noise_bound * self.u_end[m])
            out.append((b1, b2))
        return out

    def truth_fl(self) -> np.ndarray:
        """True FL positions (n - 2, 2) of landmarks 3..n."""
        return to_xy(fl(self.landmarks[2:], self.landmarks[0], self.landmarks[1]))

    def robot_truth_fl(self, move: int) -> np.ndarray:
        """True FL position (2,) of R2 of move ``move``."""
        r2 = self.poses()[move][1]
        return to_xy(fl(r2, self.landmarks[0], self.landmarks[1]))

    def transformed(self, scale: float, angle: float, shift: complex) -> Episode:
        """The same episode in a world moved by the similarity z -> a z + shift."""
        a = scale * unit(angle)
        return Episode(
            landmarks=a * self.landmarks + shift,
            start=a * self.start + shift,
            moves=[(h + angle, scale * length) for h, length in self.moves],
            u_start=self.u_start,
            u_end=self.u_end,
        )


def random_episode(
    rng: np.random.Generator,
    n_landmarks: int,
    n_moves: int,
    arena: tuple[float, float] = (1.0, 0.7),
    min_separation: float = 0.08,
    length_range: tuple[float, float] = (0.1, 0.3),
    noise: str = "uniform",
) -> Episode:
    """Random landmarks in the arena and a random polygonal trajectory inside it.

    Landmarks are at least ``min_separation`` apart (L1 and L2 at least twice that). The
    robot starts at a random point and each move is a random heading and length that keep
    it inside the arena and at least ``min_separation / 2`` from every landmark.
    ``noise="uniform"`` draws ``u`` uniformly in [-1, 1]; ``"extreme"`` draws +-1 only
    (the worst case the cones must still cover); ``"none"`` gives zeros.
    """
    w, h = arena
    pts: list[complex] = []
    while len(pts) < n_landmarks:
        z = complex(rng.uniform(0, w), rng.uniform(0, h))
        sep = 2 * min_separation if len(pts) == 1 else min_separation
        if all(abs(z - p) >= sep for p in pts):
            pts.append(z)
    landmarks = np.array(pts)
    clearance = min_separation / 2

    def ok(z: complex) -> bool:
        return 0 <= z.real <= w and 0 <= z.imag <= h and np.min(np.abs(landmarks - z)) > clearance

    start = complex(rng.uniform(0, w), rng.uniform(0, h))
    while not ok(start):
        start = complex(rng.uniform(0, w), rng.uniform(0, h))
    moves = []
    pos = start
    while len(moves) < n_moves:
        heading = rng.uniform(-np.pi, np.pi)
        length = rng.uniform(*length_range)
        end = pos + length * unit(heading)
        if ok(end):
            moves.append((heading, length))
            pos = end
    shape = (n_moves, n_landmarks)
    if noise == "uniform":
        u1, u2 = rng.uniform(-1, 1, shape), rng.uniform(-1, 1, shape)
    elif noise == "extreme":
        u1, u2 = rng.choice([-1.0, 1.0], shape), rng.choice([-1.0, 1.0], shape)
    elif noise == "none":
        u1, u2 = np.zeros(shape), np.zeros(shape)
    else:
        raise ValueError(f"unknown noise {noise!r}")
    return Episode(landmarks, start, moves, u1, u2)


def run(slam, episode: Episode, noise_bound: float, n_moves: int | None = None) -> list:
    """Feed the episode's readings to ``slam``; return the UpdateResults."""
    readings = episode.readings(noise_bound)
    if n_moves is not None:
        readings = readings[:n_moves]
    return [slam.update(b1, b2) for b1, b2 in readings]


# --------------------------------------------------------------------------------------
# Independent geometry for the FR regions (exact line intersections, no bearing_env code)
# --------------------------------------------------------------------------------------


def cone_region_vertices(b_start: float, b_end: float, eps: float, tol: float = 1e-9):
    """Vertices (complex) of the intersection of the cone at 0 (bearings b_start +- eps)
    and the cone at 1 (b_end +- eps), or None when it is unbounded or empty.

    Candidates: the 4 intersections of boundary rays and the two apexes; a candidate is a
    vertex when it lies in both (closed) cones. Unbounded when the direction ranges of the
    two cones overlap.
    """
    if abs(float(wrap(b_end - b_start))) <= 2 * eps:
        return None
    apex = (0.0 + 0j, 1.0 + 0j)
    dirs = (
        [unit(b_start - eps), unit(b_start + eps)],
        [unit(b_end - eps), unit(b_end + eps)],
    )

    def in_cone(z: complex, j: int, b: float) -> bool:
        d = z - apex[j]
        if abs(d) <= tol:
            return True
        return abs(float(wrap(angle_of(d) - b))) <= eps + tol

    cands = [0.0 + 0j, 1.0 + 0j]
    for r in dirs[0]:
        for q in dirs[1]:
            # t r = 1 + s q  ->  solve 2x2.
            m = np.array([[r.real, -q.real], [r.imag, -q.imag]])
            if abs(np.linalg.det(m)) < 1e-14:
                continue
            t, s = np.linalg.solve(m, np.array([1.0, 0.0]))
            if t >= -tol and s >= -tol:
                cands.append(t * r)
    verts = [z for z in cands if in_cone(z, 0, b_start) and in_cone(z, 1, b_end)]
    if not verts:
        return None
    return np.array(verts)
