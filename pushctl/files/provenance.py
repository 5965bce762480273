"""How a results file was made, and writing files so that none is ever half-written.

Every CSV the tool writes starts with one comment line, ``# made by: <command>; pushctl
<version>; commit <git describe>; …``. It holds no clock time, so one command with one seed
writes byte-identical files. Its last line, ``# sha256: <hex>``, is the SHA-256 of every byte
before it: :func:`csv_digest_problem` tells a file edited or cut short after it was written.
Read such files with ``pandas.read_csv(path, comment="#")``.
"""

from __future__ import annotations

import errno
import hashlib
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pandas as pd

from pushctl.errors import WriteError
from pushctl.version import VERSION

PACKAGE = Path(__file__).resolve().parents[1]
"""The package's directory: where :func:`git_commit` looks for the source tree."""


def git_commit(source: Path | None = None) -> str:
    """``git describe --always`` of the source tree (``source``: a directory in it, default
    this package's), with ``-dirty`` if a tracked file outside ``results/`` differs from the
    commit (the results a run writes do not make the code that wrote them dirty), or
    ``unknown`` outside git."""
    source = source if source is not None else PACKAGE
    try:
        described = _git(["describe", "--always"], source)
        changed = _git(
            ["status", "--porcelain", "--untracked-files=no", "--", ":/", ":(exclude,top)results"],
            source,
        )
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return f"{described}-dirty" if changed else described


def _git(arguments: list[str], where: Path) -> str:
    return subprocess.run(
        ["git", *arguments], capture_output=True, text=True, check=True, cwd=where
    ).stdout.strip()


NOT_RECORDED = frozenset({"out", "plot", "force", "workers", "address"})
"""Options that change no byte of what a command computes: where its files go (``--out``,
``--plot``), whether it may replace them, and how many processes or which Ray cluster make
them. Provenance lines leave them out, so one command run twice, into two places, writes
the same bytes; a line still names everything that decides the data."""

_NOT_RECORDED_FLAGS = frozenset({"--force"})
"""The options of :data:`NOT_RECORDED` that take no value."""


def provenance_line(command: str | None = None, extra: str = "") -> str:
    """The ``# made by:`` line; ``command`` defaults to this process's command line without
    the options of :data:`NOT_RECORDED` (:func:`recorded_argv`)."""
    command = command or " ".join([Path(sys.argv[0]).name, *recorded_argv(sys.argv[1:])])
    tail = f"; {extra}" if extra else ""
    return f"# made by: {command}; pushctl {VERSION}; commit {git_commit()}{tail}"


def recorded_argv(argv: list[str]) -> list[str]:
    """``argv`` without the options of :data:`NOT_RECORDED` and their values (``--out F``,
    ``--out=F``, ``--force``), for a script that builds its provenance line from its
    command line rather than its parsed options."""
    recorded: list[str] = []
    skip_value = False
    for word in argv:
        if skip_value:
            skip_value = False
            continue
        name = word.split("=", 1)[0]
        if word.startswith("--") and name[2:] in NOT_RECORDED:
            skip_value = "=" not in word and name not in _NOT_RECORDED_FLAGS
            continue
        recorded.append(word)
    return recorded


def write_atomic(path: Path, write: Callable[[Path], object]) -> None:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then rename it over ``path``:
    readers see the old file or the new one, never a partial one. The temporary file is
    removed if ``write`` fails, and the failure (a full disk, a read-only directory, torch's
    ``RuntimeError`` for either) becomes a :class:`~pushctl.errors.WriteError` naming
    ``path``: the file asked for, not the temporary one.

    The temporary file has the final file's name, in a hidden directory of this process
    beside it (``.NAME.PID.tmp/NAME``): a writer that records its file's name in the bytes
    (``torch.save`` names its zip archive's records after it) writes the same bytes in every
    run, where a temporary name holding the process id made two runs' ``.pt`` files differ.
    A process killed while writing leaves that directory behind; the next command holding
    the output swept it (:func:`pushctl.files.output_guard.sweep_temporaries`)."""
    path = Path(path)
    folder = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp = folder / path.name
    try:
        folder.mkdir(exist_ok=True)
        try:
            write(tmp)
            tmp.replace(path)
        finally:
            tmp.unlink(missing_ok=True)
            folder.rmdir()
    except WriteError:
        raise
    except (OSError, RuntimeError) as error:
        raise WriteError(f"cannot write {path}: {write_failure(error, path)}") from None


def write_failure(error: BaseException, path: Path) -> str:
    """Why writing ``path`` failed, in words, on one line: the system's reason for an
    ``OSError``; for torch's ``RuntimeError`` (its zip writer reports no errno) the full disk
    or read-only directory behind it when that is what the directory shows, else torch's
    message, whole words only."""
    if isinstance(error, OSError) and error.strerror:
        return error.strerror
    directory = path.parent if path.parent.exists() else Path(".")
    try:
        if shutil.disk_usage(directory).free < FULL_DISK_BYTES:
            return os.strerror(errno.ENOSPC)
    except OSError:
        pass
    if not os.access(directory, os.W_OK):
        return os.strerror(errno.EACCES)
    return one_line(str(error)) or type(error).__name__


FULL_DISK_BYTES = 1 << 20
"""Free bytes under which a failed write is put down to a full disk [B]."""


def one_line(text: str, limit: int = 160) -> str:
    """``text`` on one line (whitespace runs joined), at most ``limit`` characters, cut at a
    word boundary with an ellipsis rather than mid-word."""
    words = " ".join(text.split())
    if len(words) <= limit:
        return words
    cut = words[: limit - 1].rsplit(" ", 1)[0]
    return cut.rstrip(",;:") + " …"


def write_csv(
    path: Path,
    frame: pd.DataFrame,
    provenance: str,
    float_format: str = "%.9g",
    before_rename: Callable[[], None] | None = None,
) -> None:
    """Write ``frame`` to ``path`` atomically under its ``provenance`` line. ``before_rename``
    runs once the data is written, before the file appears (write a companion file there:
    if it fails, ``path`` is left as it was)."""

    def write(tmp: Path) -> None:
        body = frame.to_csv(index=False, float_format=float_format, lineterminator="\n")
        data = (provenance + "\n" + body).encode()
        tmp.write_bytes(data + f"{DIGEST_PREFIX}{hashlib.sha256(data).hexdigest()}\n".encode())
        if before_rename is not None:
            before_rename()

    write_atomic(path, write)


DIGEST_PREFIX = "# sha256: "
"""The start of a CSV's last line: the SHA-256 (hex) of every byte before that line."""


def csv_digest_problem(data: bytes, required: bool = False) -> str | None:
    """Why a CSV's bytes ``data`` (decompressed) do not match the digest on their last line,
    or None if they do. A file without one (written by hand, by an older pushctl, or cut
    short, or its digest removed) is a problem only if the digest is ``required``."""
    start = data.rfind(b"\n", 0, len(data) - 1) + 1
    last = data[start:]
    if not last.startswith(DIGEST_PREFIX.encode()):
        return "it has no digest line (cut short, or its digest removed)" if required else None
    recorded = last[len(DIGEST_PREFIX) :].strip().decode("ascii", "replace")
    if hashlib.sha256(data[:start]).hexdigest() != recorded:
        return "its rows do not match the digest on its last line (edited or damaged)"
    return None
