"""bearing_env: active exploration in bearing-only polygon SLAM.

The world model (:mod:`bearing_env.slam`) runs on a native C++ core and imports neither gymnasium
nor pygame. Importing this package registers the Gymnasium ids ``BearingSLAM-v1`` and
``BearingSLAMDiscrete-v1``, their tasks (:mod:`bearing_env.tasks`) and the older versions
of them all (``BearingSLAM-v0``, ...) when gymnasium is installed.
"""

__version__ = "0.2.0"

try:
    import gymnasium  # noqa: F401
except ImportError:  # the world model alone (e.g. on logged robot data) needs no gymnasium
    pass
else:
    from bearing_env.registration import register_envs

    register_envs()

__all__ = ["__version__"]
