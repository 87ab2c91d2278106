"""Where the files shipped inside the package are: found through ``importlib.resources``.

The models (``bearing_env.agents``' ``pretrained/``) and the rl-zoo3 hyperparameter files
(``bearing_env.train.sb3``'s ``hyperparams/``) are package data, so they are where the
package is, in a checkout (editable install) and in site-packages alike, and nothing
looks for them relative to the working directory. pip installs a wheel as plain files,
so a shipped folder is a real directory that other programs (rl-zoo3's ``--conf-file``)
can open.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path


def shipped_dir(package: str, folder: str) -> Path:
    """The directory ``folder`` shipped inside ``package`` (``"bearing_env.agents"``,
    ``"pretrained"``), as a file-system path."""
    return Path(str(files(package).joinpath(folder)))
