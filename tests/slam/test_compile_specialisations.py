"""The compiled core compiles each kernel once per argument layout, never once more for a
literal argument.

numba types a constant argument (``0``, ``1``, ``False``, or a variable that starts as
one and is widened later in a loop) as a literal, and compiles the called kernel, with
all it calls, once more for it: such duplicates cost the first Khepera step about 20 s
of its compile (see the performance page's compile notes). A fresh process with an
empty cache records numba's compile events for a first env step, with each fusion.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

#: Steps each fusion's env from an empty cache and prints, per project kernel, the
#: argument lists it was compiled for that hold a literal type.
FIRST_STEPS = textwrap.dedent(
    """
    import json
    from numba.core import event, types

    literal = {}
    with event.install_recorder("numba:compile") as recorder:
        import gymnasium as gym
        import bearing_env

        for fusion in ("intersect", "relaxed", "robust"):
            env = gym.make("BearingSLAM-v0", scenario="khepera", fusion=fusion)
            env.reset(seed=3)
            for _ in range(3):
                env.step(env.action_space.sample())
    compiled = 0
    for _, record in recorder.buffer:
        function = record.data["dispatcher"].py_func
        if not record.is_start or not str(function.__module__).startswith("bearing_env"):
            continue
        compiled += 1
        arguments = record.data["args"]
        if any(isinstance(argument, types.Literal) for argument in arguments):
            name = f"{function.__module__}.{function.__qualname__}"
            literal.setdefault(name, []).append([str(a)[:60] for a in arguments])
    print(json.dumps({"compiled": compiled, "literal": literal}))
    """
)


@pytest.mark.slow
def test_no_kernel_is_compiled_for_a_literal_argument(tmp_path: Path) -> None:
    env = {key: value for key, value in os.environ.items() if not key.startswith("NUMBA_")}
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "numba")  # empty: everything compiles
    result = subprocess.run(
        [sys.executable, "-c", FIRST_STEPS],
        capture_output=True,
        text=True,
        env=env,
        timeout=1200,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    report = json.loads(result.stdout.strip().splitlines()[-1])
    assert report["compiled"] > 50  # the core compiled here, not loaded from a cache
    # drop_edges_outward takes its capacity as a module constant (128) at three call
    # sites and a computed one at the fourth: one small extra specialisation, left as is.
    literal = {
        name: arguments
        for name, arguments in report["literal"].items()
        if not name.endswith(".drop_edges_outward")
    }
    assert literal == {}
