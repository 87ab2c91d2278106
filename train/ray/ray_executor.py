"""``bearing-env compare --executor ray``: the comparison's episodes as Ray tasks.

:func:`run_on_ray` takes the comparison's episode tasks (``compare.EpisodeTask``: label,
policy spec, env id and kwargs, seed) and yields each finished episode's record, the
record ``compare.run_task`` gives in a local worker, in the order the episodes finish.
The caller logs each record as it comes (``episodes.jsonl``), so ``--resume`` and the
progress bar work as with ``--workers N``. Every episode resets the env and the policy
with its own seed, so a record does not depend on the worker, the node or the order:
the summary equals the local one.

**Cluster.** With ``address`` (``--ray-address``, e.g. ``HEAD_IP:6379`` or ``auto``) the
tasks join that cluster; without it, a Ray instance already started in this process
(``ray.init``) is used, else a local one is started for the run and shut down after it.
Every node needs the same ``bearing_env`` installed (``pip install "bearing_env[ray]"``).

Before ``ray.init`` joins a ``HOST:PORT`` (or ``ray://HOST:PORT``) address,
:func:`check_ray_address` opens a TCP connection to it: an address that does not answer
within :data:`RAY_CONNECT_TIMEOUT` seconds is refused with a
:class:`RayAddressError` naming it (``ray.init`` itself would wait much longer, then fail
with a traceback). ``auto`` is left to Ray.

**Files.** A policy that reads files (``sb3:path=...``, ``pretrained:NAME``) gets them
through Ray's object store, not the file system: the bytes of each file
(:func:`bearing_env.agents.registry.spec_files`) are put there once, and each worker
writes them into a folder of its own temporary directory named by their digest, and
builds the policy from those copies (:func:`bearing_env.agents.registry.with_files`).

**Interruption.** Every record already yielded has been logged by the caller, so after
Ctrl-C a rerun with ``--resume`` runs only the rest. Ctrl-C ends the command, and Ray
ends its tasks with it (or with the local instance it started); a failed episode, or a
caller that stops reading, cancels the episodes not yet finished.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import socket
import tempfile
import urllib.parse
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from bearing_env.extras import require
from bearing_env.train.compare.runner import EpisodeTask, run_task

#: A policy's files as they travel: option -> (file name, bytes).
FileBundle = dict[str, tuple[str, bytes]]

__all__ = [
    "RAY_CONNECT_TIMEOUT",
    "FileBundle",
    "RayAddressError",
    "check_ray_address",
    "materialise",
    "ray_session",
    "read_bundle",
    "run_on_ray",
]

#: Seconds a Ray cluster address (``--ray-address HOST:PORT``) has to accept a TCP
#: connection before it is refused: a head node on a reachable network answers in
#: milliseconds, and 5 s leaves room for a slow VPN without hanging the command.
RAY_CONNECT_TIMEOUT = 5.0


class RayAddressError(ValueError):
    """A Ray cluster address that is malformed or does not answer."""


def check_ray_address(address: str, timeout: float = RAY_CONNECT_TIMEOUT) -> None:
    """Refuse a ``HOST:PORT`` (or ``ray://HOST:PORT``) Ray address whose port does not
    accept a TCP connection within ``timeout`` seconds (:class:`RayAddressError` naming
    it). ``auto`` and ``local`` (which Ray resolves itself) pass unchecked."""
    if address in ("auto", "local"):
        return
    malformed = f"Ray address {address!r}: expected HOST:PORT, ray://HOST:PORT or auto"
    scheme, separator, rest = address.rpartition("://")
    if separator and scheme != "ray":
        raise RayAddressError(malformed)
    try:
        parts = urllib.parse.urlsplit(f"//{rest}")
        host, port = parts.hostname, parts.port
    except ValueError:
        host = port = None
    if not host or port is None:
        raise RayAddressError(malformed)
    try:
        with socket.create_connection((host, port), timeout=timeout):
            pass
    except OSError as error:
        reason = "no answer" if isinstance(error, TimeoutError) else error.strerror or str(error)
        raise RayAddressError(
            f"Ray address {address!r} does not answer ({reason} within {timeout:g} s); "
            "is the cluster's head node running (ray start --head) and reachable?"
        ) from None


def _ray() -> Any:
    return require("ray", "--executor ray", extra="ray")


def read_bundle(spec: str) -> FileBundle:
    """The bytes of the files a policy spec reads (empty for the heuristics)."""
    from bearing_env.agents.registry import spec_files

    return {option: (path.name, path.read_bytes()) for option, path in spec_files(spec).items()}


def _bundle_digest(bundle: Mapping[str, tuple[str, bytes]]) -> str:
    digest = hashlib.sha256()
    for option in sorted(bundle):
        name, data = bundle[option]
        digest.update(f"{option}\0{name}\0{len(data)}\0".encode())
        digest.update(data)
    return digest.hexdigest()[:16]


def materialise(
    spec: str, bundle: Mapping[str, tuple[str, bytes]], root: Path | None = None
) -> str:
    """The spec of the same policy reading copies of ``bundle``'s files, written (once,
    atomically) under ``root`` (default: this machine's temporary directory) in a folder
    named by the files' digest. ``spec`` itself when the bundle is empty."""
    if not bundle:
        return spec
    from bearing_env.agents.registry import with_files

    folder = Path(root or tempfile.gettempdir()) / f"bearing_env-ray-{_bundle_digest(bundle)}"
    folder.mkdir(parents=True, exist_ok=True)
    files: dict[str, Path] = {}
    for option, (name, data) in bundle.items():
        target = folder / name
        if not (target.is_file() and target.stat().st_size == len(data)):
            temporary = folder / f".{name}.{os.getpid()}.tmp"
            temporary.write_bytes(data)
            os.replace(temporary, target)  # workers writing the same file race harmlessly
        files[option] = target
    return with_files(spec, files).to_string()


def _run_remote(task: EpisodeTask, bundle: FileBundle) -> dict[str, Any]:
    """A Ray task: one episode (``bundle`` arrives resolved from the object store)."""
    return run_task(replace(task, spec=materialise(task.spec, bundle)))


@contextlib.contextmanager
def ray_session(address: str | None = None, num_cpus: int | None = None) -> Iterator[Any]:
    """The ``ray`` module, connected: to ``address`` if given, else to the instance this
    process already runs, else to a new local instance (``num_cpus``: default all), which
    is shut down on exit. MissingExtraError without the ``ray`` extra."""
    ray = _ray()
    if address is not None and num_cpus is not None:
        raise ValueError("num_cpus applies to a local Ray instance, not to a cluster address")
    started = not ray.is_initialized()
    if started and address is not None:
        check_ray_address(address)
    if started:
        options: dict[str, Any] = {
            "address": address,
            "log_to_driver": False,  # task output would break the progress bar
            "logging_level": logging.WARNING,
            "configure_logging": True,
        }
        if address is None:
            options.update(num_cpus=num_cpus, include_dashboard=False)
        ray.init(**options)
    try:
        yield ray
    finally:
        if started:
            ray.shutdown()


def run_on_ray(
    tasks: Sequence[EpisodeTask], address: str | None = None, num_cpus: int | None = None
) -> Iterator[dict[str, Any]]:
    """Run every task as a Ray task; yield each record as its episode finishes.

    Args:
        tasks: the episodes (``compare._pending_tasks``).
        address: a running cluster to join (``ray start --head`` prints it); default the
            Ray instance of this process, or a new local one.
        num_cpus: CPUs of a new local instance (default all of this machine's).

    Raises:
        MissingExtraError: ``ray`` is not installed.
        ValueError: ``num_cpus`` with an ``address``.
    """
    if not tasks:
        return
    with ray_session(address, num_cpus) as ray:
        remote = ray.remote(num_cpus=1, max_retries=0)(_run_remote)
        bundles = {spec: ray.put(read_bundle(spec)) for spec in {task.spec for task in tasks}}
        pending = [remote.remote(task, bundles[task.spec]) for task in tasks]
        try:
            while pending:
                ready, pending = ray.wait(pending, num_returns=1)
                yield ray.get(ready[0])
        except KeyboardInterrupt:
            # The command is ending: Ray ends this driver's tasks with it (cancelling them
            # here while their replies are under way has crashed Ray's core worker).
            raise
        except BaseException:
            for ref in pending:  # failed, or the caller stopped early: drop the rest
                ray.cancel(ref)
            raise
