"""The envs' state as arrays, and the form the env kernels take it in.

:class:`BatchState` holds the world state and bookkeeping of ``N`` envs, one row each
(a structure of arrays): the arrays the native env step (``bearing_env._core.EnvInputs``)
takes views of (:data:`KERNEL_ARRAYS`, declared in the C++ library and checked once per
group), the trajectory and the noise generators.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from bearing_env import _core
from bearing_env._schema import BatchArrays
from bearing_env.belief import PoseBeliefs

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
class BatchState(BatchArrays):
    """World state and env bookkeeping of ``num_rows`` envs, one row each: the arrays the
    native step takes (:class:`~bearing_env._schema.BatchArrays`, declared in the C++
    library), and the trajectory and noise generators.

    Per-landmark arrays have ``slots`` columns (the largest landmark count a row can
    have); row ``i`` uses the first ``n_landmarks[i]`` (the rest are zeros).
    """

    #: Robot positions since the reset (N, capacity, 2), for rendering; the first
    #: ``trajectory_length[i]`` entries of row ``i`` are used.
    trajectory: FloatArray
    #: Per row, its generator (the env's ``np_random``; None before the first reset), and
    #: what rewinds it to just after the draws spent (None without a block): its state
    #: before the block, the noise model, epsilon and the landmark count. Reading ``k`` of
    #: a noise block, bearing ``j``, is value ``k * n + j``.
    noise_generators: list[Any]
    noise_marks: list[Any]
    #: What each robot believes of its pose between map fixes (for the planner features).
    beliefs: PoseBeliefs

    @classmethod
    def empty(cls, num_rows: int, slots: int) -> BatchState:
        """A batch of rows that have not been reset yet."""
        lengths = {"N": num_rows, "slots": slots, "values": max(NOISE_BLOCK_VALUES, 2 * slots)}
        arrays = _core.new_arrays("BatchState", lengths)
        state = cls(
            **dict(zip(KERNEL_ARRAYS, arrays, strict=True)),
            trajectory=np.zeros((num_rows, INITIAL_TRAJECTORY_SLOTS, 2)),
            noise_generators=[None] * num_rows,
            noise_marks=[None] * num_rows,
            beliefs=PoseBeliefs(num_rows),
        )
        state.frame_unit[:] = 1.0
        state.start_bearings[:] = np.nan
        state.start_positions[:] = np.nan
        return state

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
KERNEL_ARRAYS: tuple[str, ...] = tuple(f.name for f in fields(BatchArrays))
