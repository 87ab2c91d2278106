"""The world model's settings: one frozen, validated :class:`MapSettings`.

Everything a map needs besides its landmark count: the bearing error bound and how
regions are transferred and fused. :class:`~bearing_env.slam.BatchedPolygonSLAM` and
:class:`~bearing_env.slam.PolygonSLAM` validate their keyword arguments by building one
(``batch.settings``), and take one whole with ``from_settings``. It is hashable and
comparable, so the envs key their map batches by it (``EnvConfig.map_settings``: maps
with equal settings can share a batch) and policies rebuild a map from an info with it.
"""

from __future__ import annotations

from dataclasses import dataclass

from bearing_env.slam import kernels
from bearing_env.slam.transfer import TRANSFERS
from bearing_env.validation import epsilon_radians, float_in, int_at_least

#: What a landmark's region becomes when a movement's region misses it.
INCONSISTENCY_POLICIES = ("restart", "keep")

#: How a landmark's regions from successive movements are combined: ``"intersect"``, the
#: paper's intersection, ``"relaxed"``, the q-relaxed intersection over a window, or
#: ``"robust"``, nested relaxed sets with the number left out from a risk target.
FUSIONS = ("intersect", "relaxed", "robust")

#: Which of the robust fusion's two sets a map reports: the ``"guaranteed"`` one (enough
#: regions left out for the risk target) or the ``"likely"`` one (only the
#: contradicting regions left out).
ROBUST_SETS = ("guaranteed", "likely")

#: Which bound the robust fusion reads bearings with: its ``"estimate"`` (epsilon,
#: grown when the data show it too small) or the ``"nominal"`` epsilon throughout.
NOISE_BOUNDS = ("estimate", "nominal")

# The kernels take the transfer, the policy and the fusion as indices into these tuples.
if (
    TRANSFERS.index("conservative") != kernels.TRANSFER_CONSERVATIVE
    or TRANSFERS.index("paper") != kernels.TRANSFER_PAPER
    or TRANSFERS.index("conservative_global") != kernels.TRANSFER_CONSERVATIVE_GLOBAL
    or INCONSISTENCY_POLICIES.index("restart") != kernels.INCONSISTENCY_RESTART
    or INCONSISTENCY_POLICIES.index("keep") != kernels.INCONSISTENCY_KEEP
    or FUSIONS.index("intersect") != kernels.FUSION_INTERSECT
    or FUSIONS.index("relaxed") != kernels.FUSION_RELAXED
    or FUSIONS.index("robust") != kernels.FUSION_ROBUST
):
    raise ImportError("the kernels' transfer, policy or fusion codes disagree with the names")

#: The relaxed fusion's defaults: movements kept per map, and the most regions per
#: landmark it may leave out of the window.
DEFAULT_WINDOW = 8
DEFAULT_MAX_OUTLIERS = 2
#: The robust fusion's default risk: the chance, under the estimated contamination rate,
#: that more of a landmark's regions are contaminated than its guaranteed set leaves out.
DEFAULT_RISK = 0.05


@dataclass(frozen=True)
class MapSettings:
    """The settings of a map (see :class:`~bearing_env.slam.PolygonSLAM`'s Args, which
    take the same names): validated and normalised to plain Python types on
    construction, so equal settings give equal, equally hashed objects.

    Invalid values raise ``TypeError`` or ``ValueError`` naming the value.
    """

    epsilon: float
    transfer: str = "conservative"
    edge_samples: int = 3
    on_inconsistency: str = "restart"
    fusion: str = "intersect"
    max_outliers: int = DEFAULT_MAX_OUTLIERS
    window: int = DEFAULT_WINDOW
    risk: float = DEFAULT_RISK
    robust_set: str = "guaranteed"
    noise_bound: str = "estimate"

    def __post_init__(self) -> None:
        def normalise(name: str, value: object) -> None:
            object.__setattr__(self, name, value)

        normalise("epsilon", epsilon_radians(self.epsilon))
        if self.transfer not in TRANSFERS:
            raise ValueError(f"transfer must be one of {TRANSFERS}, got {self.transfer!r}")
        edge_samples = int_at_least(self.edge_samples, 1, "edge_samples")
        if edge_samples > kernels.MAX_EDGE_SAMPLES:
            raise ValueError(
                f"edge_samples must be <= {kernels.MAX_EDGE_SAMPLES}, got {self.edge_samples!r}"
            )
        normalise("edge_samples", edge_samples)
        if self.on_inconsistency not in INCONSISTENCY_POLICIES:
            raise ValueError(
                f"on_inconsistency must be one of {INCONSISTENCY_POLICIES}, "
                f"got {self.on_inconsistency!r}"
            )
        if self.fusion not in FUSIONS:
            raise ValueError(f"fusion must be one of {FUSIONS}, got {self.fusion!r}")
        window = int_at_least(self.window, 1, "window")
        if window > kernels.MAX_WINDOW:
            raise ValueError(f"window must be <= {kernels.MAX_WINDOW}, got {self.window!r}")
        normalise("window", window)
        max_outliers = int_at_least(self.max_outliers, 0, "max_outliers")
        if max_outliers >= window:
            raise ValueError(f"max_outliers must be < window ({window}), got {self.max_outliers!r}")
        normalise("max_outliers", max_outliers)
        normalise("risk", float_in(self.risk, "risk", 0.0, 0.5, closed_low=False))
        if self.robust_set not in ROBUST_SETS:
            raise ValueError(f"robust_set must be one of {ROBUST_SETS}, got {self.robust_set!r}")
        if self.noise_bound not in NOISE_BOUNDS:
            raise ValueError(f"noise_bound must be one of {NOISE_BOUNDS}, got {self.noise_bound!r}")


class HasMapSettings:
    """The map settings as read-only attributes (``slam.epsilon``, ``slam.fusion``, ...),
    read from ``self.settings``, their one home, for the batch and its single-map views."""

    settings: MapSettings

    @property
    def epsilon(self) -> float:
        return self.settings.epsilon

    @property
    def transfer(self) -> str:
        return self.settings.transfer

    @property
    def edge_samples(self) -> int:
        return self.settings.edge_samples

    @property
    def on_inconsistency(self) -> str:
        return self.settings.on_inconsistency

    @property
    def fusion(self) -> str:
        return self.settings.fusion

    @property
    def max_outliers(self) -> int:
        return self.settings.max_outliers

    @property
    def window(self) -> int:
        return self.settings.window

    @property
    def risk(self) -> float:
        return self.settings.risk

    @property
    def robust_set(self) -> str:
        return self.settings.robust_set

    @property
    def noise_bound(self) -> str:
        return self.settings.noise_bound
