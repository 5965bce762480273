"""Checked ``.pt`` files: checkpoints and policies saved with a digest of their content and
refused in one line when damaged.

Two checks on load, both cheap (a 16 MB checkpoint in about 0.1 s):

- the zip archive's CRC-32 of every record (``torch.save`` writes a zip whose records carry
  their checksum, which ``torch.load`` does not read): flipped bytes anywhere in the tensors
  or the pickle are caught, in every file torch ever wrote, the shipped ``results/`` ones
  included;
- ``digest``, the SHA-256 of the saved content (every tensor's dtype, shape and bytes, every
  other value's ``repr``, keys in sorted order) stored beside it by :func:`save_checked`:
  it catches a file loaded, changed and saved again, which carries valid CRCs. A file
  without the key (its digest removed, or written before the key existed) is refused unless
  the caller trusts it (``trust_undigested``, the commands' ``--trust-undigested``): then it
  is accepted on the CRCs alone.
"""

from __future__ import annotations

import hashlib
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import torch

from pushctl.errors import ConfigError, DamagedFileError
from pushctl.files.provenance import one_line, write_atomic

CHECKPOINT_FORMAT = 1
"""Bumped when a checkpoint's layout changes; an older one is refused, not misread."""
TRUST_OPTION = "--trust-undigested"
"""The commands' option that accepts a file without its digest."""
DIGEST_KEY = "digest"
"""The key of a saved dict that holds :func:`content_digest` of the rest."""


def content_digest(state: Any) -> str:
    """SHA-256 (hex) of ``state``: nested dicts (keys sorted), lists, tuples, tensors and
    numpy arrays (dtype, shape, bytes) and plain values (``repr``)."""
    digest = hashlib.sha256()
    _feed(digest, state)
    return digest.hexdigest()


def _feed(digest: Any, value: Any) -> None:
    if isinstance(value, torch.Tensor):
        flat = value.detach().cpu().contiguous().reshape(-1)
        digest.update(f"T{value.dtype}{tuple(value.shape)}".encode())
        digest.update(flat.view(torch.uint8).numpy().tobytes() if flat.numel() else b"")
    elif isinstance(value, np.ndarray):
        digest.update(f"A{value.dtype}{value.shape}".encode())
        digest.update(np.ascontiguousarray(value).tobytes())
    elif isinstance(value, dict):
        digest.update(b"{")
        for key in sorted(value, key=repr):
            _feed(digest, key)
            _feed(digest, value[key])
        digest.update(b"}")
    elif isinstance(value, (list, tuple)):
        digest.update(b"[" if isinstance(value, list) else b"(")
        for item in value:
            _feed(digest, item)
        digest.update(b"]")
    else:
        digest.update(f"{type(value).__name__}:{value!r};".encode())


def save_checked(path: Path, state: dict[str, Any]) -> None:
    """``torch.save`` ``state`` with its :func:`content_digest` under :data:`DIGEST_KEY`, to
    a temporary file beside ``path`` renamed over it (WriteError naming ``path``)."""
    signed = {**state, DIGEST_KEY: content_digest(state)}
    write_atomic(Path(path), lambda tmp: torch.save(signed, tmp))


def load_checked(path: Path, kind: str, *, trust_undigested: bool = False) -> dict[str, Any]:
    """The dict saved in ``path``, its digest checked and removed; DamagedFileError (one line
    naming the ``kind`` of file, ``"checkpoint"``) if it is empty, not a torch file,
    damaged, not a dict, or without its digest (unless ``trust_undigested``). The caller
    checks that the file exists."""
    size = path.stat().st_size
    if size == 0:
        raise DamagedFileError(f"{kind} {path} is empty (0 bytes): not a {kind}")
    try:
        with zipfile.ZipFile(path) as archive:
            damaged = archive.testzip()
    except Exception as exc:  # zipfile raises several types for a damaged archive
        raise DamagedFileError(
            f"{kind} {path} is not a {kind} or is cut short ({one_line(str(exc), 80)})"
        ) from None
    if damaged is not None:
        raise DamagedFileError(f"{kind} {path} is damaged: its record {damaged} fails its checksum")
    try:
        state = torch.load(path, weights_only=True)
    except Exception as exc:  # torch raises many types for a damaged file
        raise DamagedFileError(
            f"{kind} {path} is corrupt or not a {kind}: {one_line(str(exc), 120)}"
        ) from None
    if not isinstance(state, dict):
        raise DamagedFileError(f"{kind} {path} holds a {type(state).__name__}, not a {kind}")
    stored = state.pop(DIGEST_KEY, None)
    if stored is None and not trust_undigested:
        raise DamagedFileError(
            f"{kind} {path} has no digest, so an edit to it cannot be detected; pass "
            f"{TRUST_OPTION} if you trust it"
        )
    if stored is not None and stored != content_digest(state):
        raise DamagedFileError(
            f"{kind} {path} was changed after it was written: its content does not match its digest"
        )
    return state


def nonfinite_entry(tensors: dict[str, Any]) -> str | None:
    """The name of the first tensor in ``tensors`` (a state dict) holding NaN or ±inf."""
    for name, value in tensors.items():
        if isinstance(value, torch.Tensor) and value.is_floating_point():
            if not bool(torch.isfinite(value).all()):
                return name
    return None


def read_checkpoint(path: Path, *, trust_undigested: bool = False) -> dict[str, Any]:
    """A training checkpoint's contents; ConfigError if missing, damaged (checksums or
    digest), without its digest (unless ``trust_undigested``) or of another format."""
    if not path.is_file():
        raise ConfigError(f"no checkpoint at {path}: start a run without --resume")
    state = load_checked(path, "checkpoint", trust_undigested=trust_undigested)
    if state.get("format") != CHECKPOINT_FORMAT:
        raise ConfigError(
            f"checkpoint {path} has format {state.get('format')!r}; "
            f"this pushctl reads {CHECKPOINT_FORMAT}"
        )
    return state
