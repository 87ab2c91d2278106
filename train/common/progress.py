"""Progress bars on long work: tqdm's when it is installed (the ``train`` extra), a
silent stand-in otherwise or when the user turned them off (``--no-progress``)."""

from __future__ import annotations

from typing import Any

from bearing_env.extras import available


class NoProgress:
    """Stands in for a tqdm bar: a context manager whose ``update`` does nothing."""

    def __enter__(self) -> NoProgress:
        return self

    def __exit__(self, *exc_info: object) -> None:
        return None

    def update(self, n: int = 1) -> None:
        pass

    def set_postfix(self, **values: Any) -> None:
        pass


def progress_bar(total: int, *, desc: str, unit: str, enabled: bool, initial: int = 0) -> Any:
    """A bar over ``total`` units (``initial`` of them done already), to use as a context
    manager and ``update(n)``."""
    if not enabled or not available("tqdm"):
        return NoProgress()
    from tqdm.auto import tqdm

    return tqdm(total=total, initial=initial, unit=unit, desc=desc, dynamic_ncols=True)
