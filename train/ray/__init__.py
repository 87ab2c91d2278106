"""Ray: ``compare --executor ray``, ``bearing-env rllib`` and ``bearing-env sweep``.

Every import in the project is absolute, so ``import ray`` (and ``require("ray")``) inside
this package is always the real Ray, never this package."""
