"""The I/O home: JSON-safe values and safe, all-or-nothing output files and folders.

Every command checks its output paths with :func:`check_output_file` or :class:`OutputDir`
*before* it starts work, and writes through :func:`atomic_write_text`,
:func:`atomic_write_bytes`, :func:`atomic_path` or :class:`OutputDir`, so an output file is either
complete or absent and an output folder never holds a mix of two runs.
"""

from __future__ import annotations

from .outputs import (
    MANIFEST,
    OutputDir,
    atomic_path,
    atomic_write_bytes,
    atomic_write_text,
    check_output_dir,
    check_output_file,
)
from .plain import dumps_json, to_plain

__all__ = [
    "MANIFEST",
    "OutputDir",
    "atomic_path",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_output_dir",
    "check_output_file",
    "dumps_json",
    "to_plain",
]
