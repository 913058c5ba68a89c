"""The main job: a demo of the whole pipeline on bundled data (``stringstab demo``).

Each capability of the toolkit contributes one *step*: a function
``step(out: Path, log: Callable[[str], None]) -> dict`` that writes its outputs
under ``out`` and returns a small summary.  :func:`run_demo` runs them in order
and writes ``summary.json``.  The whole demo runs in a few minutes at most.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["STEPS", "run_demo"]

Log = Callable[[str], None]
Step = Callable[[Path, Log], dict[str, Any]]


def _step_derive(out: Path, log: Log) -> dict[str, Any]:
    """Derive Γ(s), Ψ1-Ψ3, Λ and compare with the printed formulas."""
    from .cli import main

    for fmt, name in (("json", "derive.json"), ("latex", "derive.tex"), ("text", "derive.txt")):
        main(["derive", "--errata", "--format", fmt, "--out", str(out / name)])
    doc = json.loads((out / "derive.json").read_text())
    wrong = [f"eq {e['equation']} ({e['key']})" for e in doc["errata"] if not e["matches"]]
    log(f"derived Γ(s) = {doc['gamma']}")
    log(f"errata: {len(wrong)} printed formulas differ from the derivation: {', '.join(wrong)}")
    return {"files": ["derive.json", "derive.tex", "derive.txt"], "errata": wrong}


#: The demo's steps, in order: (name, function).  Later capabilities append here.
STEPS: list[tuple[str, Step]] = [
    ("derive", _step_derive),
]


def run_demo(out: str | Path, *, log: Log = print, only: list[str] | None = None) -> dict[str, Any]:
    """Run every demo step, writing outputs under ``out``.

    Parameters
    ----------
    out : path
        Output directory (created if needed).
    log : callable
        Receives one line of progress at a time.
    only : list of str, optional
        Run only the named steps.

    Returns
    -------
    dict
        ``{step: summary}``, also written to ``out/summary.json``.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summary: dict[str, Any] = {}
    for name, step in STEPS:
        if only and name not in only:
            continue
        t0 = time.perf_counter()
        log(f"== {name} ==")
        d = out / name
        d.mkdir(exist_ok=True)
        result = step(d, log)
        result["seconds"] = round(time.perf_counter() - t0, 2)
        summary[name] = result
        log(f"   ({result['seconds']} s, outputs in {d})")
    (out / "summary.json").write_text(json.dumps(summary, indent=2, ensure_ascii=False) + "\n")
    return summary
