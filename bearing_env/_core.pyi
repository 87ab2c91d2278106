# Type stub of the native extension bearing_env._core (built from csrc/ by CMakeLists.txt).
# Its names are checked against the built module by tests/slam/test_native_stub.py.

from typing import Any

import numpy as np
from numpy.typing import NDArray

class CapacityError(RuntimeError):
    """A fixed-capacity buffer of the native core would overflow (a bug or an absurd input)."""

# ---- The batched map update (csrc/bindings/bind_slam_update.cpp; keep in step with it) ----

CAPACITY: int
MAX_EDGE_SAMPLES: int
FR_VERTICES: int
MAX_SAMPLES: int
MAX_PAIRS: int
SCRATCH: int
MAX_CLOUD: int
MAX_WINDOW: int
MAX_LANDMARKS: int
ROBUST_LEVELS: int
HISTORY: int
FR_BOUNDED: int
FR_UNBOUNDED: int
FR_EMPTY: int
FR_MISSING: int
FRAME_OK: int
FRAME_L1_UNBOUNDED: int
FRAME_L2_UNBOUNDED: int
FRAME_L1_L2_OVERLAP: int
FRAME_L1_L2_TOO_CLOSE: int
FRAME_L1_MISSING: int
FRAME_L2_MISSING: int
FRAME_REJECTED: int
LANDMARK_UPDATED: int
LANDMARK_UNBOUNDED: int
LANDMARK_INCONSISTENT: int
LANDMARK_SKIPPED: int
LANDMARK_MISSING: int
TRANSFER_CONSERVATIVE: int
TRANSFER_PAPER: int
INCONSISTENCY_RESTART: int
INCONSISTENCY_KEEP: int
FUSION_INTERSECT: int
FUSION_RELAXED: int
FUSION_ROBUST: int
INDEX_OK: int
INDEX_OUT_OF_RANGE: int
INDEX_REPEATED: int
MAX_FR_EXTENT: float
RELATIVE_TOLERANCE: float
PROBE_SHRINK: float
BOUND_GROWTH: float
MAX_NOISE_SCALE: float
MAX_BOUND: float
PRIOR_CONTRADICTIONS: float
PRIOR_REGIONS: float
UNSEEN_FACTOR: float

class MapState:
    """A batch's state (a bearing_env.slam.kernels.State of 34 arrays), checked once."""

    def __init__(self, state: tuple[NDArray[Any], ...]) -> None: ...
    @property
    def state(self) -> tuple[NDArray[Any], ...]: ...
    @property
    def num_maps(self) -> int: ...
    @property
    def n_mapped(self) -> int: ...
    @property
    def window(self) -> int: ...
    @property
    def levels(self) -> int: ...
    @property
    def history(self) -> int: ...

class Params:
    """One update call's settings (bearing_env.slam.kernels.Params), validated."""

    def __init__(
        self,
        epsilon: float,
        transfer: int,
        edge_samples: int,
        on_inconsistency: int,
        fusion: int,
        max_outliers: int,
        with_robot: bool,
        risk: float,
        likely: bool,
        estimate_bound: bool,
    ) -> None: ...
    @property
    def epsilon(self) -> float: ...
    @property
    def transfer(self) -> int: ...
    @property
    def edge_samples(self) -> int: ...
    @property
    def on_inconsistency(self) -> int: ...
    @property
    def fusion(self) -> int: ...
    @property
    def max_outliers(self) -> int: ...
    @property
    def with_robot(self) -> bool: ...
    @property
    def risk(self) -> float: ...
    @property
    def likely(self) -> bool: ...
    @property
    def estimate_bound(self) -> bool: ...

def update_maps(
    bearings_start: NDArray[np.float64],
    bearings_end: NDArray[np.float64],
    rows: NDArray[np.int64],
    params: Params,
    state: MapState,
    out: tuple[NDArray[np.int8], NDArray[np.int8], NDArray[np.int64]],
    threads: int = 1,
) -> None: ...
def check_indices(indices: NDArray[np.int64], size: int, distinct: bool) -> int: ...
def none_infinite(values: NDArray[np.float64]) -> bool: ...
def contains_points(
    vertices: NDArray[np.complex128],
    counts: NDArray[np.int64],
    rows: NDArray[np.int64],
    points: NDArray[np.complex128],
    relative: float,
    out: NDArray[np.bool_],
) -> None: ...
def binomial_q(n: int, p: float, risk: float, q_cap: int) -> int: ...
