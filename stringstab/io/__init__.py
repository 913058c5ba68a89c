"""The I/O home: result tables, JSON-safe values and safe, all-or-nothing output files and folders.

:mod:`~stringstab.io.gains` reads gain files for every command (the table and its checks in
:mod:`~stringstab.io.gain_table`, the readers of CSV and JSON in :mod:`~stringstab.io.gain_text`
and of NPZ and Parquet in :mod:`~stringstab.io.gain_arrays`);
:mod:`~stringstab.io.platoon_logs` reads recorded platoons (OpenACC, plain CSV, NGSIM pairs) for
``stringstab identify``;
:mod:`~stringstab.io.results` writes every command's result columns (table, JSON, CSV,
Parquet, NPZ) with one vectorised writer: the column model is :mod:`~stringstab.io.columns`,
the renderers :mod:`~stringstab.io.table`, :mod:`~stringstab.io.text_formats` and
:mod:`~stringstab.io.binary_formats`; :mod:`~stringstab.io.figures` saves a drawn figure in every
format with its metadata; :mod:`~stringstab.io.text_input` reads a user's text file
(plain or gzip, by content) as UTF-8 or refuses it in one line; :mod:`~stringstab.io.manifest` says which command wrote a folder.

Every command checks its output paths with :func:`check_output_file` or :class:`OutputDir`
*before* it starts work, and writes through :func:`atomic_write_text`,
:func:`atomic_write_bytes`, :func:`atomic_path` or :class:`OutputDir`, so an output file is either
complete or absent and an output folder never holds a mix of two runs.
"""

from __future__ import annotations

from .columns import Categorical, columns_from_records, flatten_columns, records_from_columns
from .figures import FIGURE_FORMATS, check_figure_formats, figure_metadata, save_figure
from .gain_table import GAIN_COLUMNS, OPTIONAL_COLUMNS, GainTable
from .gains import INPUT_FORMATS, parse_triple, read_gains
from .manifest import MANIFEST, claim_folder, read_manifest
from .outputs import (
    OutputDir,
    atomic_path,
    atomic_write_bytes,
    atomic_write_text,
    check_output_dir,
    check_output_file,
    write_manifest,
)
from .plain import dumps_json, to_plain
from .platoon_logs import PlatoonLog, Segment, clean_segments, read_platoon_logs
from .results import BINARY_FORMATS, RESULT_FORMATS, format_results, write_results, write_text
from .table import TableColumn, render_table

__all__ = [
    "BINARY_FORMATS",
    "FIGURE_FORMATS",
    "GAIN_COLUMNS",
    "INPUT_FORMATS",
    "MANIFEST",
    "OPTIONAL_COLUMNS",
    "RESULT_FORMATS",
    "Categorical",
    "GainTable",
    "OutputDir",
    "PlatoonLog",
    "Segment",
    "TableColumn",
    "atomic_path",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_figure_formats",
    "check_output_dir",
    "check_output_file",
    "claim_folder",
    "clean_segments",
    "columns_from_records",
    "dumps_json",
    "figure_metadata",
    "flatten_columns",
    "format_results",
    "parse_triple",
    "read_gains",
    "read_manifest",
    "read_platoon_logs",
    "records_from_columns",
    "render_table",
    "save_figure",
    "to_plain",
    "write_manifest",
    "write_results",
    "write_text",
]
