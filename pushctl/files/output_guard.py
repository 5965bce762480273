"""No result is overwritten by accident: the checks every writing command makes before it works.

A command refuses, with one line naming ``--force``, to write

- into an output *directory* that already holds files (``pushctl evaluate``, ``pushctl train``),
- over an output *file* that already exists (``plan``/``simulate`` ``--out``/``--plot``,
  ``tune-pd``, ``report``'s tables and figures, ``python -m benchmarks.suite``,
  ``python -m studies.pd_sweep``),

unless the user passed ``--force``. The checks run before any work, so a refused command
costs nothing; the files are then written atomically
(:func:`pushctl.files.provenance.write_atomic`), so a file this run wrote is replaced only
by a file the same run wrote.

One command at a time: before its check, a command takes an exclusive lock on its output
(:func:`hold`; a directory's ``.pushctl.lock``, a file's ``.NAME.lock`` beside it, both
``fcntl.flock`` locks, which the system drops when the process ends, killed or not) and holds
it until it returns; a directory not made yet is made first, so the lock is held before
anything is written there. A second command writing there meanwhile is refused in one line. The
lock file is removed when the command ends; a killed command's one is left, unlocked, and
counts as nothing. The hidden temporary folders of a killed command's writes
(``.NAME.PID.tmp/``) count as nothing either, and the next command holding the directory
removes them (:func:`sweep_temporaries`).
"""

from __future__ import annotations

import atexit
import os
import re
import shutil
from collections.abc import Iterable
from pathlib import Path

from pushctl.errors import ConfigError

LOCK_NAME = ".pushctl.lock"
"""The lock file of an output directory."""
_TEMPORARY = re.compile(r"^\..+\.(\d+)\.tmp$")
"""A temporary folder of :func:`pushctl.files.provenance.write_atomic`: ``.NAME.PID.tmp``."""
_held: dict[Path, int] = {}
"""Lock file → open descriptor, for the locks this process holds."""
_created: dict[Path, list[Path]] = {}
"""Lock file → the directories this process created for it (deepest first): removed again
on release if the command left them empty (a refused or failed command leaves no empty
directory)."""


def refuse_existing_files(option: str, paths: Iterable[Path | None], force: bool) -> None:
    """ConfigError if any of ``paths`` (None entries skipped) already exists, unless ``force``.
    Each path is locked for this command first (:func:`hold`).

    ``option`` names the command-line option the paths come from (``--out``), for the
    message."""
    for path in paths:
        if path is not None:
            hold(option, path)
    if force:
        return
    for path in paths:
        if path is not None and path.exists():
            raise ConfigError(
                f"{option}: {path} already exists; pass --force to overwrite it, "
                "or choose another path"
            )


def refuse_occupied_dir(option: str, directory: Path, force: bool) -> None:
    """ConfigError if ``directory`` exists and holds anything, unless ``force``. The
    directory is locked for this command first (:func:`hold`); its lock file and a killed
    command's temporary folders do not count."""
    hold(option, directory, directory=True)
    if force or not directory.is_dir():
        return
    if occupied(directory):
        raise ConfigError(
            f"{option}: {directory} is not empty; pass --force to overwrite the results in it, "
            "or choose another directory"
        )


def occupied(directory: Path) -> bool:
    """Whether ``directory`` holds anything but lock files and temporary write folders."""
    if not directory.is_dir():
        return False
    return any(not is_ours(entry.name) for entry in directory.iterdir())


def is_ours(name: str) -> bool:
    """Whether an entry of an output directory is a lock file or a temporary write folder:
    nothing a user's result is in."""
    lock = name.startswith(".") and name.endswith(".lock")
    return lock or _TEMPORARY.match(name) is not None


def hold(option: str, path: Path, *, directory: bool = False) -> None:
    """Lock ``path`` (an output file, or with ``directory`` an output directory) for this
    command until it returns; ConfigError (one line) if another process holds it. Taking a
    lock this process already holds does nothing. A directory that does not exist yet (the
    output directory, or an output file's directory) is created first, so the lock is held
    before anything is written there, and removed again on release if the command wrote
    nothing into it; then the killed commands' temporary folders in it are removed. The
    lock is released when the command returns (the click context closes), else when the
    process exits."""
    path = Path(path)
    if directory:
        if path.exists() and not path.is_dir():
            raise ConfigError(f"{option} {path} is a file; give a directory")
        home, lock = path, path / LOCK_NAME
    else:
        home, lock = path.parent, path.with_name(f".{path.name}.lock")
        if home.exists() and not home.is_dir():
            return  # the command's own check reports a file where its directory should be
    made = _make_directory(option, home)
    key = lock.absolute()
    if key in _held:
        return
    try:
        descriptor = _acquire(option, path, lock)
    except ConfigError:
        _remove_empty(made)
        raise
    _held[key] = descriptor
    if made:
        _created[key] = made
    _release_when_done(key)
    if directory:
        sweep_temporaries(path)


def _make_directory(option: str, directory: Path) -> list[Path]:
    """Create ``directory`` and its missing parents; return those created, deepest first."""
    missing = [d for d in (directory, *directory.parents) if not d.exists()]
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise ConfigError(f"{option}: cannot create {directory}: {error.strerror}") from None
    return [d.absolute() for d in missing]


def _acquire(option: str, path: Path, lock: Path) -> int:
    """An open descriptor of ``lock`` holding its exclusive lock. A lock file removed by
    its holder between our open and our lock is opened again (else two processes could
    each hold a lock on a different file of one name)."""
    import fcntl

    while True:
        try:
            descriptor = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as error:
            raise ConfigError(f"{option}: cannot lock {path}: {error.strerror}") from None
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = _read_holder(descriptor)
            os.close(descriptor)
            raise ConfigError(
                f"{option}: {path} is in use by another pushctl command{holder}; wait for it "
                "to finish or choose another path"
            ) from None
        try:
            same = os.fstat(descriptor).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if same:
            _write_holder(descriptor)
            return descriptor
        os.close(descriptor)


def _write_holder(descriptor: int) -> None:
    """Write this process's id into its lock file, for the message of a refused command; on
    a full disk the lock holds without it (the command's own writes then say why)."""
    try:
        os.ftruncate(descriptor, 0)
        os.write(descriptor, f"{os.getpid()}\n".encode())
    except OSError:
        pass


def _read_holder(descriptor: int) -> str:
    try:
        text = os.pread(descriptor, 32, 0).decode().strip()
    except OSError:
        return ""
    return f" (process {text})" if text.isdigit() else ""


def _release_when_done(key: Path) -> None:
    """Release ``key`` when the process exits, if the command has not (``pushctl``'s
    commands release every lock when they return: :func:`release`, from the app)."""
    atexit.register(release, key)


def release(lock: Path | None = None) -> None:
    """Give up the lock on ``lock`` (a lock file's absolute path), or every lock this
    process holds, removing the lock files."""
    for key in [lock] if lock is not None else list(reversed(_held)):
        descriptor = _held.pop(key, None)
        if descriptor is None:
            continue
        try:
            key.unlink(missing_ok=True)  # while still locked: no one else holds this file
        except OSError:
            pass
        os.close(descriptor)
        _remove_empty(_created.pop(key, []))


def _remove_empty(directories: list[Path]) -> None:
    """Remove ``directories`` (deepest first) while they are empty."""
    for directory in directories:
        try:
            directory.rmdir()
        except OSError:
            break


def sweep_temporaries(directory: Path) -> list[Path]:
    """Remove the temporary write folders (``.NAME.PID.tmp/``) in ``directory`` whose
    process is no longer running (a killed command's); return them."""
    swept = []
    for entry in directory.iterdir():
        found = _TEMPORARY.match(entry.name)
        if found is None or not entry.is_dir() or _running(int(found.group(1))):
            continue
        shutil.rmtree(entry, ignore_errors=True)
        swept.append(entry)
    return swept


def _running(pid: int) -> bool:
    if pid == os.getpid():
        return False  # this process writes nothing before it holds the directory
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
