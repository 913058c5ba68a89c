"""Arguments and helpers shared by the sub-commands (one definition of each).

Defined in three modules by job and importable from here as before:
:mod:`~stringstab.cli._model_args` (the vehicle, τ, δ, T*, H: ``integer``, ``loop_params``,
``shown_params``, ``warn_beyond_sensible``, ``check_horizon``, ...),
:mod:`~stringstab.cli._output_args` (gains in, results out: ``gains_from_args``,
``check_output``, ``resolve_format``, ...) and :mod:`~stringstab.cli._limit_args` (the
followers' limits and their leaders).  Here: :data:`NEGATIVE_NUMBER`.
"""

from __future__ import annotations

import re

from ._limit_args import add_limit_arguments as add_limit_arguments
from ._limit_args import checked_leaders as checked_leaders
from ._limit_args import limits_from_args as limits_from_args
from ._model_args import add_model_arguments as add_model_arguments
from ._model_args import add_vehicle_arguments as add_vehicle_arguments
from ._model_args import check_horizon as check_horizon
from ._model_args import integer as integer
from ._model_args import loop_params as loop_params
from ._model_args import shown_params as shown_params
from ._model_args import warn_beyond_sensible as warn_beyond_sensible
from ._output_args import add_gain_arguments as add_gain_arguments
from ._output_args import add_output_arguments as add_output_arguments
from ._output_args import check_output as check_output
from ._output_args import gains_from_args as gains_from_args
from ._output_args import resolve_format as resolve_format

__all__ = ["NEGATIVE_NUMBER"]

#: argparse (< 3.13) reads "-0.5,1,1" or "-2,2" as an unknown option; anything that
#: starts like a negative number (or -inf/-nan, rejected later with a clear
#: message) is a value.  Installed on every sub-parser by ``stringstab.cli``.
NEGATIVE_NUMBER = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)
