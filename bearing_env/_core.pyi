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

# ---- The polygon and frame kernels (csrc/bindings/bind_slam_geometry.cpp; keep in step) ----
# Same signatures and return conventions as bearing_env.slam.kernels' numba kernels: `out`
# arrays (complex128, C-contiguous, writeable) are written in place; `frame` is a
# bearing_env.slam.kernels.FrameChange (a tuple of 11).

def cross(a: complex, b: complex) -> float: ...
def dot(a: complex, b: complex) -> float: ...
def wrap(angle: float) -> float: ...
def scale_of(poly: NDArray[np.complex128], n: int) -> tuple[float, float]: ...
def tolerance_of(size: float, magnitude: float) -> float: ...
def convex_hull(
    points: NDArray[np.complex128], n_points: int, out: NDArray[np.complex128]
) -> int: ...
def small_convex_hull(
    points: NDArray[np.complex128], n_points: int, out: NDArray[np.complex128], tol: float
) -> int: ...
def small_hull_indices(
    points: NDArray[np.complex128], n_points: int, out: NDArray[np.int64], tol: float
) -> int: ...
def area_centroid(poly: NDArray[np.complex128], n: int) -> tuple[float, complex]: ...
def contains_point(
    poly: NDArray[np.complex128], n: int, point: complex, relative: float
) -> bool: ...
def polygon_distance(
    p: NDArray[np.complex128], n_p: int, q: NDArray[np.complex128], n_q: int
) -> float: ...
def longest_edge(poly: NDArray[np.complex128], n: int) -> float: ...
def simplify(poly: NDArray[np.complex128], n: int, tol: float) -> int: ...
def drop_edges_outward(poly: NDArray[np.complex128], n: int, capacity: int) -> int: ...
def clip_convex(
    subject: NDArray[np.complex128],
    n_subject: int,
    clipper: NDArray[np.complex128],
    n_clipper: int,
    out: NDArray[np.complex128],
    work: NDArray[np.complex128],
) -> int: ...
def offset_outward(
    poly: NDArray[np.complex128], n: int, radius: float, out: NDArray[np.complex128]
) -> int: ...
def cone_region(
    a: float, b: float, epsilon: float, out: NDArray[np.complex128]
) -> tuple[int, int]: ...
def boundary_samples(
    poly: NDArray[np.complex128], n: int, per_edge: int, out: NDArray[np.complex128]
) -> int: ...
def frame_plan(
    a1: NDArray[np.complex128],
    n1: int,
    a2: NDArray[np.complex128],
    n2: int,
    conservative: bool,
    edge_samples: int,
) -> tuple[int, int, float, float, float]: ...
def sample_hypotheses(
    a1: NDArray[np.complex128],
    n1: int,
    a2: NDArray[np.complex128],
    n2: int,
    per_edge: int,
    h1: NDArray[np.complex128],
    inv_d: NDArray[np.complex128],
) -> int: ...
def transfer_region(
    target: NDArray[np.complex128],
    n_target: int,
    frame: tuple[Any, ...],
    cloud: NDArray[np.complex128],
    hull: NDArray[np.complex128],
    out: NDArray[np.complex128],
) -> int: ...
