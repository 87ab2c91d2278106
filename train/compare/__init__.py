"""``bearing-env compare``: exploration policies on the same evaluation episodes (the
command line in :mod:`~bearing_env.train.compare.cli`)."""
