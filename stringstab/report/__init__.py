"""One document per run: ``report.md`` and a self-contained ``report.html``.

Every command that writes a folder builds a :class:`Report` from the result objects it already
has and writes it beside its other outputs.  The report says what was run (the exact command,
the parameters, the toolkit's version), gives every verdict, table and figure (each figure with a
caption saying what to see in it) and the run's wall time.  One renderer turns it into Markdown
(Jinja2 template) and the Markdown into HTML (Python-Markdown), with every figure embedded as
base64 and every formula (``$…$`` in the Markdown) typeset at build time as an embedded SVG
(:mod:`stringstab.report.maths`), so the HTML needs neither the folder, nor a script, nor a
network to be read.

Building a report (the API the commands use)::

    from stringstab.report import Report

    rep = Report("Region map", command=command_line(args), params={"tau": 0.1})
    sec = rep.section("Verdict")
    sec.verdict("K = (1.2, 0.5, 0.6)", True, "sup|Γ| = 0.93")
    sec.table([{"k_x": 1.2, "verdict": "certified"}], caption="Gains checked")
    sec.figure("region_class_exact.png")            # caption from :data:`CAPTIONS`
    rep.write(out)                                   # an OutputDir or a folder path

Figures are given by their path relative to the output folder; a caption not given is looked up
in :data:`stringstab.report.captions.CAPTIONS` by file name.
"""

from __future__ import annotations

from .captions import CAPTIONS, caption_for
from .render import Report, Section, command_line

__all__ = ["CAPTIONS", "Report", "Section", "caption_for", "command_line"]
