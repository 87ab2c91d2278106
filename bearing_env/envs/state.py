"""The envs' state as arrays, and the form the env kernels take it in.

:class:`BatchState` holds the world state and bookkeeping of ``N`` envs, one row each
(a structure of arrays); its field list is the only place these arrays are listed
(:data:`STATE_ARRAYS`). The native env step (``bearing_env._core.EnvInputs``) takes
views of :data:`KERNEL_ARRAYS`, checked once per group.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from bearing_env import _core

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
ComplexArray = NDArray[np.complex128]

#: Trajectory slots allocated per row at first; the array doubles when a row fills it.
INITIAL_TRAJECTORY_SLOTS = 32
#: Noise values (one per bearing of a reading) a row's noise buffer holds, at least: a
#: block of whole moves (two readings of ``n`` bearings each), up to ``max_moves`` of
#: them, is drawn at once (see ``core.fill_noise``). 512 holds 64 moves of 4 landmarks.
NOISE_BLOCK_VALUES = 512


@dataclass
class BatchState:
    """World state and env bookkeeping of ``num_rows`` envs, one row each.

    Per-landmark arrays have ``slots`` columns (the largest landmark count a row can
    have); row ``i`` uses the first ``n_landmarks[i]`` (the rest are zeros).
    """

    #: Landmarks in each row's current episode.
    n_landmarks: IntArray
    #: True landmark positions (N, slots, 2), metres; L1 first.
    landmarks: FloatArray
    #: True robot positions (N, 2), metres, and headings (N,), radians CCW from +x.
    positions: FloatArray
    headings: FloatArray
    #: FL frame per row: FL = (world - origin) / unit, as complex numbers (fixed per episode).
    frame_origin: ComplexArray
    frame_unit: ComplexArray
    #: True FL positions (N, slots - 2) of landmarks L3.., for the info.
    landmarks_fl: ComplexArray
    #: Moves made this episode, and the potential Phi after the latest one.
    moves: IntArray
    potentials: FloatArray
    #: The latest reading (N, slots), relative to the current heading.
    latest_bearings: FloatArray
    #: The last movement's first reading and start position (NaN before the first move).
    start_bearings: FloatArray
    start_positions: FloatArray
    #: Flags of the last movement: it changed frames (updated the map); the wall stopped it.
    frame_changed: BoolArray
    blocked: BoolArray
    #: Whether the episode has ended (terminated or truncated) and needs a reset.
    done: BoolArray
    #: Robot positions since the reset (N, capacity, 2), for rendering; the first
    #: ``trajectory_length[i]`` entries of row ``i`` are used.
    trajectory: FloatArray
    trajectory_length: IntArray
    #: Each row's movement noise, drawn ahead in blocks from its generator (see
    #: ``core.fill_noise``): per value, the offset, whether it is an outlier (or a miss)
    #: and its replacement bearing. Reading ``k`` of the block, bearing ``j``, is value
    #: ``k * n + j``; ``noise_used`` values of the ``noise_filled`` ones are spent.
    noise_offsets: FloatArray
    noise_is_outlier: BoolArray
    noise_replacement: FloatArray
    noise_used: IntArray
    noise_filled: IntArray
    #: Per row, its generator (the env's ``np_random``; None before the first reset), and
    #: what rewinds it to just after the draws spent (None without a block): its state
    #: before the block, the noise model, epsilon and the landmark count.
    noise_generators: list[Any]
    noise_marks: list[Any]

    @classmethod
    def empty(cls, num_rows: int, slots: int) -> BatchState:
        """A batch of rows that have not been reset yet."""
        n = num_rows
        return cls(
            n_landmarks=np.zeros(n, dtype=np.int64),
            landmarks=np.zeros((n, slots, 2)),
            positions=np.zeros((n, 2)),
            headings=np.zeros(n),
            frame_origin=np.zeros(n, dtype=complex),
            frame_unit=np.ones(n, dtype=complex),
            landmarks_fl=np.zeros((n, slots - 2), dtype=complex),
            moves=np.zeros(n, dtype=np.int64),
            potentials=np.zeros(n),
            latest_bearings=np.zeros((n, slots)),
            start_bearings=np.full((n, slots), np.nan),
            start_positions=np.full((n, 2), np.nan),
            frame_changed=np.zeros(n, dtype=bool),
            blocked=np.zeros(n, dtype=bool),
            done=np.zeros(n, dtype=bool),
            trajectory=np.zeros((n, INITIAL_TRAJECTORY_SLOTS, 2)),
            trajectory_length=np.zeros(n, dtype=np.int64),
            noise_offsets=np.zeros((n, max(NOISE_BLOCK_VALUES, 2 * slots))),
            noise_is_outlier=np.zeros((n, max(NOISE_BLOCK_VALUES, 2 * slots)), dtype=bool),
            noise_replacement=np.zeros((n, max(NOISE_BLOCK_VALUES, 2 * slots))),
            noise_used=np.zeros(n, dtype=np.int64),
            noise_filled=np.zeros(n, dtype=np.int64),
            noise_generators=[None] * n,
            noise_marks=[None] * n,
        )

    @property
    def num_rows(self) -> int:
        return int(self.n_landmarks.shape[0])

    def append_positions(self, rows: IntArray) -> None:
        """Record the rows' current positions in their trajectories."""
        rows = np.ascontiguousarray(rows, dtype=np.int64)
        if not _core.append_positions(
            rows, self.positions, self.trajectory, self.trajectory_length
        ):
            self.grow_trajectory()
            _core.append_positions(rows, self.positions, self.trajectory, self.trajectory_length)

    def grow_trajectory(self) -> None:
        """Double the trajectory's capacity (for every row): some row has filled it."""
        capacity = self.trajectory.shape[1]
        grown = np.zeros((self.num_rows, 2 * capacity, 2))
        grown[:, :capacity] = self.trajectory
        self.trajectory = grown

    def __getstate__(self) -> dict[str, Any]:
        return dict(self.__dict__)

    def __setstate__(self, state: dict[str, Any]) -> None:
        # An out-of-band pickle may hand back read-only buffers: the arrays (all written)
        # are copied then, the writable ones kept. In place, so that the state keeps its
        # identity: the env's world views hold it.
        self.__dict__.update(
            {
                key: np.require(value, requirements=["W"])
                if isinstance(value, np.ndarray)
                else value
                for key, value in state.items()
            }
        )


#: The state's arrays, in field order.
STATE_ARRAYS: tuple[str, ...] = tuple(f.name for f in fields(BatchState))
#: The arrays the native step takes views of: all but the trajectory, the one array that is
#: replaced (when it grows; the step kernel takes it as an argument), so that a
#: reference, once made, stays valid, and the noise marks (Python objects).
KERNEL_ARRAYS: tuple[str, ...] = tuple(
    name for name in STATE_ARRAYS if name not in ("trajectory", "noise_generators", "noise_marks")
)
