"""The measured record names a commit that exists, and lists the tracked files that
differed from it, instead of a bare ``+changes``."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from bearing_env.train.common import provenance


def git(folder: Path, *arguments: str) -> str:
    return subprocess.run(
        ["git", *arguments], cwd=folder, capture_output=True, text=True, check=True
    ).stdout


@pytest.fixture
def checkout(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A git checkout of one committed file, which provenance reads instead of ours."""
    git(tmp_path, "init", "-q")
    (tmp_path / "code.py").write_text("x = 1\n", encoding="utf-8")
    git(tmp_path, "add", "code.py")
    git(tmp_path, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "one")

    def in_checkout(*arguments: str) -> str:
        return git(tmp_path, *arguments)

    monkeypatch.setattr(provenance, "_git", in_checkout)
    return tmp_path


def test_a_clean_tree_records_its_commit_and_no_uncommitted_file(checkout: Path) -> None:
    record = provenance.measured_record("bearing-env x --y")
    assert record["commit"] == git(checkout, "rev-parse", "HEAD").strip()
    assert record["uncommitted"] == []
    sentence = provenance.measured_sentence(record, "r.json")
    assert f"commit `{record['commit'][:7]}`, on a" in sentence


def test_a_dirty_tree_records_the_clean_commit_and_its_changed_files(checkout: Path) -> None:
    (checkout / "code.py").write_text("x = 2\n", encoding="utf-8")
    (checkout / "untracked.txt").write_text("not part of the code\n", encoding="utf-8")
    record = provenance.measured_record("bearing-env x")
    assert record["commit"] == git(checkout, "rev-parse", "HEAD").strip()
    assert "+" not in record["commit"]
    assert record["uncommitted"] == ["code.py"]
    sentence = provenance.measured_sentence(record, "r.json")
    assert f"commit `{record['commit'][:7]}` with uncommitted changes to `code.py`" in sentence


def test_a_plus_changes_commit_is_refused_by_the_caption() -> None:
    with pytest.raises(ValueError, match="not a commit"):
        provenance.short_commit("4a8bc8e1a124837b2911b2f82079a00b70e1c36d+changes")


def test_outside_a_checkout_there_is_no_commit(monkeypatch: pytest.MonkeyPatch) -> None:
    def no_git(*arguments: str) -> str:
        raise OSError("no git")

    monkeypatch.setattr(provenance, "_git", no_git)
    assert provenance.source_commit() is None
    assert provenance.uncommitted_files() == []
