"""Input files: regular files only, read with a size cap, text decoded or refused in one line.

A FIFO (named pipe) would block a reader forever, ``/dev/zero`` would fill memory, a folder or a
socket is no document: each is refused in one line naming what it is, before any byte is read
(:func:`check_input`). Files are opened without blocking and checked again on the open
descriptor, so a path swapped for a pipe between the check and the read cannot hang either.
Text is UTF-8 (a byte-order mark is dropped) or UTF-16/UTF-32 declared by a byte-order mark;
UTF-16 without a mark is recognised by its zero bytes. Anything else is refused naming the
first byte that is not UTF-8, unless the caller lists fallback encodings (a testing machine's
Windows export, say). The size caps are :mod:`colonsim.limits`.
"""

from __future__ import annotations

import codecs
import os
import re
import stat
from pathlib import Path

from colonsim.errors import ColonsimError
from colonsim.limits import DOCUMENT_MAX_BYTES

_KINDS = ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"), (stat.S_ISDIR, "a folder"))
_BOMS = ((codecs.BOM_UTF32_LE, "utf-32"), (codecs.BOM_UTF32_BE, "utf-32"), (codecs.BOM_UTF8, "utf-8-sig"),
         (codecs.BOM_UTF16_LE, "utf-16"), (codecs.BOM_UTF16_BE, "utf-16"))
_BINARY = re.compile(r"[\x00-\x08\x0e-\x1a\x1c-\x1f\x7f]")


def _size(n) -> str:
    return f"{n / 2**20:.0f} MB" if n >= 2**20 else f"{n:,} bytes"


def _not_regular(path, mode, what) -> ColonsimError | None:
    for test, kind in _KINDS:
        if test(mode):
            fix = "give the file itself" if kind == "a folder" else "give a regular file (save the stream to a file first)"
            return ColonsimError(f"{what} {path} is {kind}, not a file; {fix}")
    return None


def _stat_error(path, what, exc: OSError) -> ColonsimError:
    if isinstance(exc, FileNotFoundError):
        return ColonsimError(f"{what} {path} not found; check the path")
    if isinstance(exc, NotADirectoryError):
        return ColonsimError(f"{what} {path} not found (a part of the path is a file); check the path")
    return ColonsimError(f"cannot read {what} {path} ({exc.strerror or exc}); check its permissions")


def check_input(path, what, max_bytes=DOCUMENT_MAX_BYTES) -> Path:
    """``path`` as an input file: it exists, is a regular file (not a FIFO, device, socket or
    folder) and holds at most ``max_bytes``. Nothing is opened, so a FIFO cannot block.

    Raises
    ------
    ColonsimError
        One line naming ``what`` (e.g. "centerline file"), the path, the problem and the fix.
    """
    path = Path(path)
    try:
        info = os.stat(path)
    except OSError as exc:
        raise _stat_error(path, what, exc) from None
    problem = _not_regular(path, info.st_mode, what)
    if problem is not None:
        raise problem
    if info.st_size > max_bytes:
        raise ColonsimError(f"{what} {path} holds {_size(info.st_size)}, more than the {_size(max_bytes)} an input "
                            "may hold; give a smaller file (or split it)")
    return path


def read_input(path, what, max_bytes=DOCUMENT_MAX_BYTES) -> bytes:
    """The bytes of the input file ``path`` (see :func:`check_input`), read with the cap enforced
    on the open file too (a file that grows while read is refused, not read without end)."""
    path = check_input(path, what, max_bytes)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
    except OSError as exc:
        raise _stat_error(path, what, exc) from None
    try:
        problem = _not_regular(path, os.fstat(fd).st_mode, what)  # swapped after the check
        if problem is not None:
            raise problem
        chunks, size = [], 0
        while size <= max_bytes:
            chunk = os.read(fd, min(1 << 20, max_bytes + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:
        raise ColonsimError(f"cannot read {what} {path} ({exc.strerror or exc}); check the file and the disk") from None
    finally:
        os.close(fd)
    if size > max_bytes:
        raise ColonsimError(f"{what} {path} grew past the {_size(max_bytes)} an input may hold while it was read; "
                            "give a finished file")
    return b"".join(chunks)


def _bomless_utf16(raw: bytes) -> str | None:
    """``"utf-16-le"``/``"utf-16-be"`` when ``raw`` looks like UTF-16 text without a byte-order mark
    (ASCII text in UTF-16 has a zero byte in every pair), else None."""
    head = raw[:400]
    if len(head) < 4 or len(head) % 2:
        head = head[:len(head) - len(head) % 2]
    if len(head) < 4:
        return None
    even, odd = head[0::2], head[1::2]
    if odd.count(0) > 0.8 * len(odd) and even.count(0) < 0.1 * len(even):
        return "utf-16-le"
    if even.count(0) > 0.8 * len(even) and odd.count(0) < 0.1 * len(odd):
        return "utf-16-be"
    return None


def decode_text(raw: bytes, path, what, fallbacks=()) -> tuple[str, str]:
    """(text, encoding) of ``raw``: UTF-8, or the encoding a byte-order mark declares, or UTF-16
    recognised without one, else the first of ``fallbacks`` that decodes; one-line error otherwise."""
    declared = next((enc for bom, enc in _BOMS if raw.startswith(bom)), None) or _bomless_utf16(raw)
    candidates = (declared,) if declared else ("utf-8", *fallbacks)
    for encoding in candidates:
        try:
            text = raw.decode(encoding)
            break
        except UnicodeDecodeError as exc:
            error = exc
    else:
        if declared:
            raise ColonsimError(f"{what} {path} declares {declared.upper()} but does not decode as it; save it as "
                                "UTF-8 text") from None
        line = raw[:error.start].count(b"\n") + 1
        raise ColonsimError(f"{what} {path} is not UTF-8 text (byte 0x{raw[error.start]:02x} on line {line}; "
                            "Latin-1 or Windows-1252?); save it as UTF-8") from None
    binary = _BINARY.search(text)
    if binary:
        line = text[:binary.start()].count("\n") + 1
        raise ColonsimError(f"{what} {path} holds binary bytes (0x{ord(binary.group()):02x} on line {line}), "
                            "not text; give the text file itself")
    return text, {"utf-8-sig": "utf-8"}.get(encoding, encoding)


def read_input_text(path, what, max_bytes=DOCUMENT_MAX_BYTES, fallbacks=()) -> str:
    """The text of the input file ``path``: :func:`read_input`, then :func:`decode_text`."""
    return decode_text(read_input(path, what, max_bytes), path, what, fallbacks)[0]
