"""Progress bars: tqdm's when enabled and installed, a silent stand-in otherwise."""

from __future__ import annotations

from bearing_env.train.common import progress
from bearing_env.train.common.progress import NoProgress, progress_bar
from tests.extras import needs


def test_a_disabled_bar_is_the_silent_stand_in(capsys):
    with progress_bar(10, desc="x", unit="it", enabled=False) as bar:
        assert isinstance(bar, NoProgress)
        bar.update(3)
        bar.set_postfix(ret=1.0)
    assert capsys.readouterr().err == ""


@needs("train", "tqdm")
def test_an_enabled_bar_is_tqdm_counting_from_initial(monkeypatch):
    with progress_bar(10, desc="work", unit="it", enabled=True, initial=4) as bar:
        bar.update(2)
        assert type(bar).__module__.startswith("tqdm") and bar.n == 6 and bar.total == 10
    monkeypatch.setattr(progress, "available", lambda *_: False)  # no train extra
    assert isinstance(progress_bar(10, desc="work", unit="it", enabled=True), NoProgress)
