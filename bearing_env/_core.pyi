# Type stub of the native extension bearing_env._core (built from csrc/ by CMakeLists.txt).
# Its names are checked against the built module by tests/slam/test_native_stub.py.

from typing import Any

import numpy as np
from numpy.typing import NDArray

class CapacityError(RuntimeError):
    """A fixed-capacity buffer of the native core would overflow (a bug or an absurd input)."""

# ---- The batched map update (csrc/bindings/bind_slam_update.cpp; keep in step with it) ----

CAPACITY: int
CONTACT_SLACK: float
ELONGATION_LIMIT: float
ROBOT_BLOCK: int
LANDMARK_BLOCK: int
BEARING_BLOCK: int
SHAPE_BLOCK: int
MAX_EDGE_SAMPLES: int
FR_VERTICES: int
MAX_SAMPLES: int
MAX_PAIRS: int
SCRATCH: int
MAX_CLOUD: int
MAX_WINDOW: int
PARALLEL_MIN_MAPS: int
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
TRANSFER_CONSERVATIVE_GLOBAL: int
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
def copy_maps(from_state: MapState, rows: NDArray[np.int64], to_state: MapState) -> None: ...
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
def relaxed_region(
    state: MapState,
    row: int,
    j: int,
    slots: NDArray[np.int64],
    use_base: bool,
    max_outliers: int,
    out: NDArray[np.complex128],
) -> tuple[int, int]: ...
def update_levels(state: MapState, row: int, j: int, fresh: NDArray[np.complex128]) -> None: ...

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
def transfer_polygon(
    target: NDArray[np.complex128],
    a1: NDArray[np.complex128],
    a2: NDArray[np.complex128],
    transfer: int,
    edge_samples: int,
    out: NDArray[np.complex128],
) -> tuple[int, int]: ...
def sub_square_growths(
    target: NDArray[np.complex128],
    a1: NDArray[np.complex128],
    a2: NDArray[np.complex128],
    per_edge: int,
    out: NDArray[np.float64],
) -> tuple[int, int]: ...

# ---- The simulator (csrc/bindings/bind_sim.cpp; keep in step with it) ----
# Same signatures and return conventions as the numba kernels of bearing_env.world and
# bearing_env.sensing; `out` arrays are written in place. Obstacles are packed:
# vertices (V, 2) float64, starts (k + 1,) int64.

def _add_wrapped(
    true_bearings: NDArray[np.float64], offsets: NDArray[np.float64], out: NDArray[np.float64]
) -> None: ...
def _add_wrapped_with_outliers(
    true_bearings: NDArray[np.float64],
    offsets: NDArray[np.float64],
    is_outlier: NDArray[np.bool_],
    replacement: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None: ...
def bearing(landmark_x: float, landmark_y: float, x: float, y: float, heading: float) -> float: ...
def straight_move(
    x: float,
    y: float,
    heading: float,
    length: float,
    width: float,
    height: float,
    margin: float,
    min_baseline: float,
) -> tuple[float, float, float, bool]: ...
def obstructed_move(
    x: float,
    y: float,
    heading: float,
    length: float,
    settings: tuple[float, float, float, float],
    vertices: NDArray[np.float64],
    starts: NDArray[np.int64],
) -> tuple[float, float, float, bool]: ...
def _true_bearings_into(
    landmarks: NDArray[np.float64],
    positions: NDArray[np.float64],
    headings: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None: ...
def _edge_entry(
    x: float,
    y: float,
    dx: float,
    dy: float,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    margin: float,
) -> float: ...
def _disc_entry(
    x: float, y: float, dx: float, dy: float, cx: float, cy: float, r: float
) -> float: ...
def free_length(
    x: float,
    y: float,
    heading: float,
    vertices: NDArray[np.float64],
    starts: NDArray[np.int64],
    margin: float,
) -> float: ...
def _cross(ox: float, oy: float, ax: float, ay: float, bx: float, by: float) -> float: ...
def segments_cross(
    px: float, py: float, qx: float, qy: float, ax: float, ay: float, bx: float, by: float
) -> bool: ...
def _on_segment(ax: float, ay: float, bx: float, by: float, px: float, py: float) -> bool: ...
def line_of_sight(
    x: float,
    y: float,
    target_x: float,
    target_y: float,
    vertices: NDArray[np.float64],
    starts: NDArray[np.int64],
) -> bool: ...
def visible(
    x: float,
    y: float,
    heading: float,
    target_x: float,
    target_y: float,
    half_fov: float,
    max_range: float,
    vertices: NDArray[np.float64],
    starts: NDArray[np.int64],
) -> bool: ...
def inside_polygon(
    x: float, y: float, vertices: NDArray[np.float64], first: int, last: int
) -> bool: ...
def _segment_distance(x: float, y: float, ax: float, ay: float, bx: float, by: float) -> float: ...
def clearance(
    x: float, y: float, vertices: NDArray[np.float64], starts: NDArray[np.int64]
) -> float: ...
def visible_rows(
    landmarks: NDArray[np.float64],
    positions: NDArray[np.float64],
    headings: NDArray[np.float64],
    half_fov: float,
    max_range: float,
    vertices: NDArray[np.float64],
    starts: NDArray[np.int64],
    out: NDArray[np.bool_],
) -> None: ...

# ---- The env step (csrc/bindings/bind_env.cpp; keep in step with it) ----
# The kernels of bearing_env.envs.kernels, bearing_env.envs.robot_map and agents.planning.
# A report is kernels.Report's 16 arrays in order (a Report or a plain tuple); the encoded
# robot map is robot_map.encode_map's 12 arrays (complex ones as complex128). A map state
# (`state` of the codec) is a MapState, a bearing_env.slam.kernels.State tuple, an object
# with State's arrays as attributes (a BatchedPolygonSLAM) or an EnvInputs (its maps).

STEP_DONE: int
STEP_NEEDS_NOISE: int
STEP_NEEDS_TRAJECTORY: int
ACTIONS_OK: int
ACTIONS_NOT_FINITE: int
ACTIONS_OUTSIDE: int

class EnvInputs:
    """A group's kernel inputs, made once per group and state: its kernels.Settings, the
    map update's Params and MapState, the envs' BatchState (arrays checked and kept)."""

    def __init__(self, settings: Any, params: Params | Any, maps: Any, state: Any) -> None: ...
    @property
    def n(self) -> int: ...
    @property
    def num_rows(self) -> int: ...
    @property
    def observation_size(self) -> int: ...

class StepOutputs:
    """A group's step outputs, made once: a report's arrays (a step writes their first
    len(rows) rows), the encoded robot map's (or None) and the step's buffers."""

    def __init__(
        self,
        inputs: EnvInputs,
        report: tuple[NDArray[Any], ...],
        encoded: tuple[NDArray[Any], ...] | None = None,
    ) -> None: ...
    @property
    def capacity(self) -> int: ...
    @property
    def with_map(self) -> bool: ...

def step_rows(
    rows: NDArray[np.int64],
    turns: NDArray[np.float64],
    lengths: NDArray[np.float64],
    inputs: EnvInputs,
    trajectory: NDArray[np.float64],
    threads: int,
    outputs: StepOutputs,
    with_map: bool,
) -> int: ...
def new_report(size: int, inputs: EnvInputs) -> tuple[NDArray[Any], ...]: ...
def report_rows_into(
    rows: NDArray[np.int64], inputs: EnvInputs, outputs: StepOutputs, with_map: bool
) -> None: ...
def potentials(rows: NDArray[np.int64], inputs: EnvInputs, out: NDArray[np.float64]) -> None: ...
def move_and_read(
    row: int,
    turn: float,
    length: float,
    inputs: EnvInputs,
    reading_start: NDArray[np.float64],
    reading_end: NDArray[np.float64],
) -> float: ...
def append_positions(
    rows: NDArray[np.int64],
    positions: NDArray[np.float64],
    trajectory: NDArray[np.float64],
    lengths: NDArray[np.int64],
) -> bool: ...
def capped(area: float, floor: float, cap: float) -> float: ...
def potential_of(
    areas: NDArray[np.float64], n_mapped: int, log_area: bool, floor: float, cap: float
) -> float: ...
def _write_shape(
    vertices: NDArray[np.complex128], count: int, out: NDArray[np.float32], j: int
) -> None: ...
def decode_continuous(
    actions: NDArray[np.float32] | NDArray[np.float64],
    lo: float,
    hi: float,
    turns: NDArray[np.float64],
    lengths: NDArray[np.float64],
) -> int: ...
def _known(value: complex) -> complex: ...
def encode_map(state: Any, rows: NDArray[np.int64], slots: int) -> tuple[NDArray[Any], ...]: ...
def encode_map_into(
    state: Any, rows: NDArray[np.int64], encoded: tuple[NDArray[Any], ...]
) -> None: ...
def encode_window(state: Any, rows: NDArray[np.int64], slots: int) -> tuple[NDArray[Any], ...]: ...
def encode_levels(state: Any, rows: NDArray[np.int64], slots: int) -> tuple[NDArray[Any], ...]: ...
def _potentials_of_rows(
    rows: NDArray[np.float64], log_area: bool, floor: float, cap: float, out: NDArray[np.float64]
) -> None: ...
def _move_ends(
    start: complex,
    headings: NDArray[np.float64],
    distances: NDArray[np.float64],
    out: NDArray[np.complex128],
) -> None: ...
