# Type stub of the native extension bearing_env._core (built from csrc/ by CMakeLists.txt).
# Its names are checked against the built module by tests/slam/test_native_stub.py.

class CapacityError(RuntimeError):
    """A fixed-capacity buffer of the native core would overflow (a bug or an absurd input)."""
