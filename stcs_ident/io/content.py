"""A file's identity by its content: what lets ``track`` skip records it has processed, however renamed."""

from __future__ import annotations

import hashlib
import os

__all__ = ["content_id"]


def content_id(path: str | os.PathLike, chunk: int = 1 << 20) -> str:
    """SHA-256 of the file's bytes (hex, 32 characters), read in chunks."""
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        while block := stream.read(chunk):
            digest.update(block)
    return digest.hexdigest()[:32]
