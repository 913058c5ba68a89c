"""The report's model (:class:`Report`, :class:`Section`) and its one renderer.

A report is a title, what was run (command, parameters, version, date, wall time) and a list of
sections; a section holds blocks in order: text, verdicts, tables, figures, preformatted text and
Markdown written elsewhere (an evaluation's or a verification's own report).  :meth:`Report.markdown`
renders them through the Jinja2 template :data:`~stringstab.report.templates.MARKDOWN`;
:meth:`Report.html` converts that Markdown with Python-Markdown and wraps it in
:data:`~stringstab.report.templates.HTML`, every local figure inlined as a base64 ``data:`` URI.
"""

from __future__ import annotations

import base64
import datetime as _dt
import math
import mimetypes
import os
import re
import shlex
import sys
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .captions import caption_for
from .maths import split_maths, typeset_html

__all__ = ["Report", "Section", "command_line", "format_value", "warm_renderer"]


def warm_renderer() -> None:
    """Import and build what :meth:`Report.write` renders with: Markdown and the templates.

    A command that waits on other work (``stringstab region`` while its figures are drawn)
    pays for these imports then, not after.
    """
    import markdown  # noqa: F401  (imported for its cost now; used by Report.html)

    from .templates import environment

    environment()


def format_value(v: Any, digits: int = 4) -> str:
    """A value as a table shows it: floats to ``digits`` significant figures, None as ``n/a``.

    Parameters
    ----------
    v : any
        The value (number, bool, None, string, list, mapping with ``mean``/``std``).
    digits : int, optional
        Significant figures of a float.

    Returns
    -------
    str
        The text of the cell.

    Examples
    --------
    >>> format_value(1.234567), format_value(None), format_value(True), format_value([0.1, 0.25])
    ('1.235', 'n/a', 'yes', '0.1, 0.25')
    >>> format_value({"mean": 0.5, "std": 0.01, "n": 3})
    '0.5 ± 0.01'
    """
    if v is None:
        return "n/a"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        if not math.isfinite(v):
            return str(v)
        return f"{v:.{digits}g}"
    if isinstance(v, Mapping) and "mean" in v:
        return f"{format_value(v['mean'], 3)} ± {format_value(v.get('std'), 2)}"
    if isinstance(v, (list, tuple)):
        return ", ".join(format_value(x, digits) for x in v)
    if hasattr(v, "item") and callable(v.item):  # numpy scalar
        return format_value(v.item(), digits)
    return str(v)


def _cell(text: str) -> str:
    """Markdown-table-safe plain text: pipes and asterisks (T*, not emphasis) escaped, one line."""
    return _plain(str(text)).replace("|", "\\|").replace("\n", " ")


def _plain(text: str) -> str:
    """Plain text inside Markdown: an asterisk is a character (T*), not emphasis.

    Formulas (``$…$``) and code are left as they are (``T^*`` in TeX is not escaped).
    """
    return "".join(src if tex is not None or src.startswith("`")
                   else src.replace("\\*", "*").replace("*", "\\*")
                   for src, tex, _ in split_maths(text))


def command_line(args: Any = None) -> str:
    """The command that is running, as a user would type it.

    The process's own arguments when it was started as ``stringstab`` (or ``python -m
    stringstab``); otherwise (the command called from Python, e.g. ``stringstab.cli.main([...])``)
    the sub-command and the parsed arguments of ``args``, marked as such.

    Parameters
    ----------
    args : argparse.Namespace, optional
        The parsed arguments of the running sub-command.

    Returns
    -------
    str
        A shell-quoted command line.
    """
    argv0 = Path(sys.argv[0]).name if sys.argv and sys.argv[0] else ""
    if argv0 == "stringstab" or sys.argv[0].endswith(os.path.join("stringstab", "__main__.py")):
        return shlex.join(["stringstab", *sys.argv[1:]])
    if args is None:
        return "stringstab (called from Python)"
    skip = {"func", "command"}
    parts = [f"{k}={v!r}" for k, v in sorted(vars(args).items())
             if k not in skip and not k.startswith("_") and not callable(v)]
    return f"stringstab {getattr(args, 'command', '')} (called from Python with {', '.join(parts)})"


@dataclass
class _Block:
    kind: str
    data: dict[str, Any]


@dataclass
class Section:
    """A titled part of a report; its methods add blocks in reading order and return ``self``.

    Parameters
    ----------
    title : str
        Heading of the section.
    """

    title: str
    blocks: list[_Block] = field(default_factory=list)

    def text(self, markdown: str) -> Section:
        """Add a paragraph of Markdown (inline code, emphasis, links, lists).

        Parameters
        ----------
        markdown : str
            The paragraph.

        Returns
        -------
        Section
            ``self``, to chain calls.
        """
        if markdown and markdown.strip():
            self.blocks.append(_Block("text", {"text": markdown.strip()}))
        return self

    def verdict(self, what: str, passed: bool | None, detail: str = "") -> Section:
        """Add one verdict: what was checked, whether it holds, and the evidence.

        Consecutive verdicts are shown as one table.

        Parameters
        ----------
        what : str
            What was checked (e.g. ``"K = (1.2, 0.5, 0.6) string stable"``).
        passed : bool or None
            True (holds), False (does not hold) or None (a finding, neither).
        detail : str, optional
            The numbers behind it.

        Returns
        -------
        Section
            ``self``.
        """
        self.blocks.append(_Block("verdict", {"what": what, "passed": passed, "detail": detail}))
        return self

    def table(self, rows: Sequence[Mapping[str, Any]] | Sequence[Sequence[Any]], *,
              columns: Sequence[str] | None = None, caption: str = "",
              units: Mapping[str, str] | None = None, digits: int = 4) -> Section:
        """Add a table.

        Parameters
        ----------
        rows : sequence of mappings, or of sequences
            One row each: a mapping ``{column: value}`` (columns in first-seen order unless
            ``columns`` is given), or a sequence of values in the order of ``columns``.
        columns : sequence of str, optional
            Column names (required for rows given as sequences).
        caption : str, optional
            What the table shows, printed above it.
        units : mapping, optional
            ``{column: unit}``, shown in the header as ``column (unit)``.
        digits : int, optional
            Significant figures of floats.

        Returns
        -------
        Section
            ``self``.
        """
        if columns is None:
            cols: list[str] = []
            for r in rows:
                if not isinstance(r, Mapping):
                    raise ValueError("rows given as sequences need columns=")
                cols += [c for c in r if c not in cols]
        else:
            cols = list(columns)
        body = []
        for r in rows:
            vals = [r.get(c) for c in cols] if isinstance(r, Mapping) else list(r)
            body.append([format_value(v, digits) for v in vals])
        units = dict(units or {})
        head = [f"{c} ({units[c]})" if units.get(c) else c for c in cols]
        self.blocks.append(_Block("table", {"head": head, "rows": body, "caption": caption}))
        return self

    def figure(self, path: str | os.PathLike[str], caption: str | None = None) -> Section:
        """Add a figure by its path relative to the output folder.

        Parameters
        ----------
        path : path-like
            The image file (PNG, SVG, JPEG), relative to the folder the report is written to.
        caption : str, optional
            What to see in it; by default looked up by file name in
            :data:`stringstab.report.CAPTIONS`.

        Returns
        -------
        Section
            ``self``.
        """
        p = Path(path).as_posix()
        self.blocks.append(_Block("figure", {"path": p,
                                             "caption": caption or caption_for(p)}))
        return self

    def figures(self, paths: Iterable[str | os.PathLike[str]]) -> Section:
        """Add several figures, each with its registered caption.

        Parameters
        ----------
        paths : iterable of path-like
            Image files relative to the output folder.

        Returns
        -------
        Section
            ``self``.
        """
        for p in paths:
            self.figure(p)
        return self

    def code(self, text: str, language: str = "") -> Section:
        """Add preformatted text (a formula, a console line).

        Parameters
        ----------
        text : str
            The text, shown verbatim.
        language : str, optional
            Language tag of the fenced block (e.g. ``"console"``).

        Returns
        -------
        Section
            ``self``.
        """
        self.blocks.append(_Block("code", {"text": text.rstrip("\n"), "language": language}))
        return self

    def markdown(self, text: str, *, shift: int = 2) -> Section:
        """Add Markdown written elsewhere (another writer's report), headings demoted by ``shift``.

        Parameters
        ----------
        text : str
            The Markdown document.
        shift : int, optional
            Levels added to each heading so it nests under this section's.

        Returns
        -------
        Section
            ``self``.
        """
        self.blocks.append(_Block("markdown", {"text": _shift_headings(text, shift).strip()}))
        return self


def _shift_headings(md: str, by: int) -> str:
    out, fenced = [], False
    for line in md.splitlines():
        if line.lstrip().startswith("```"):
            fenced = not fenced
        if not fenced and re.match(r"#{1,6} ", line):
            line = "#" * by + line
        out.append(line)
    return "\n".join(out)


class Report:
    r"""A run's report, written as ``report.md`` and a self-contained ``report.html``.

    Parameters
    ----------
    title : str
        The report's title.
    command : str
        The exact command that produced the run (see :func:`command_line`).
    params : mapping, optional
        Parameters of the run, listed under the command (``{name: value}``).
    version : str, optional
        The toolkit's version (default: the installed ``stringstab.__version__``).
    intro : str, optional
        A paragraph of Markdown under the title: what the run answers.
    started : float, optional
        ``time.perf_counter()`` at the start of the run, for the wall time (default: now).

    Examples
    --------
    >>> rep = Report("Demo", command="stringstab demo", params={"tau": 0.1}, version="0")
    >>> _ = rep.section("Verdicts").verdict("K = (1.2, 0.5, 0.6) string stable", True, "sup|Γ| = 0.93")
    >>> print(rep.markdown(wall_time=1.5).split("## Verdicts")[1].strip())
    | what was checked | result | evidence |
    |---|---|---|
    | K = (1.2, 0.5, 0.6) string stable | **yes** | sup\|Γ\| = 0.93 |
    """

    def __init__(self, title: str, *, command: str, params: Mapping[str, Any] | None = None,
                 version: str | None = None, intro: str = "", started: float | None = None) -> None:
        if version is None:
            from .._version import __version__ as version
        self.title = title
        self.command = command
        self.params = dict(params or {})
        self.version = version
        self.intro = intro
        self.started = time.perf_counter() if started is None else started
        self.sections: list[Section] = []
        self.date = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")

    def section(self, title: str, text: str = "") -> Section:
        """Start a new section (appended after the others).

        Parameters
        ----------
        title : str
            Its heading.
        text : str, optional
            A first paragraph of Markdown.

        Returns
        -------
        Section
            The new section, to add blocks to.
        """
        s = Section(title)
        s.text(text)
        self.sections.append(s)
        return s

    @property
    def figure_paths(self) -> list[str]:
        """The paths of every figure in the report, in order."""
        return [b.data["path"] for s in self.sections for b in s.blocks if b.kind == "figure"]

    # -- rendering --------------------------------------------------------------------------
    def _blocks_markdown(self) -> list[dict[str, Any]]:
        n_fig = n_tab = 0
        sections = []
        for s in self.sections:
            parts: list[str] = []
            pending: list[dict[str, Any]] = []
            for b in s.blocks:
                d = b.data
                if b.kind == "verdict":
                    pending.append(d)
                    continue
                _flush_verdicts(pending, parts)
                if b.kind in ("text", "markdown"):
                    parts.append(d["text"])
                elif b.kind == "code":
                    parts.append(f"```{d['language']}\n{d['text']}\n```")
                elif b.kind == "table":
                    n_tab += 1
                    cap = f"*Table {n_tab}. {_plain(d['caption'])}*\n\n" if d["caption"] else ""
                    head = "| " + " | ".join(_cell(h) for h in d["head"]) + " |"
                    rule = "|" + "---|" * len(d["head"])
                    body = "\n".join("| " + " | ".join(_cell(c) for c in r) + " |" for r in d["rows"])
                    parts.append(cap + head + "\n" + rule + ("\n" + body if body else ""))
                elif b.kind == "figure":
                    n_fig += 1
                    parts.append(f"![Figure {n_fig}]({d['path']})\n\n"
                                 f"*Figure {n_fig}. {_plain(d['caption'])}* (`{d['path']}`)")
            _flush_verdicts(pending, parts)
            sections.append({"title": s.title, "parts": parts})
        return sections

    def markdown(self, *, wall_time: float | None = None) -> str:
        """The report as Markdown (figures linked by their relative paths).

        Parameters
        ----------
        wall_time : float, optional
            Seconds the run took (default: since ``started``).

        Returns
        -------
        str
            The Markdown document.
        """
        from .templates import MARKDOWN, environment

        if wall_time is None:
            wall_time = time.perf_counter() - self.started
        params = [(k, format_value(v)) for k, v in self.params.items()]
        return environment().from_string(MARKDOWN).render(
            title=self.title, intro=self.intro.strip(), command=self.command, version=self.version,
            date=self.date, wall=_duration(wall_time), params=params,
            sections=self._blocks_markdown()).strip() + "\n"

    def html(self, root: str | os.PathLike[str], *, markdown: str | None = None,
             wall_time: float | None = None) -> str:
        """The report as one HTML page with every figure embedded.

        Parameters
        ----------
        root : path-like
            The folder the figure paths are relative to.
        markdown : str, optional
            The Markdown to convert (default: :meth:`markdown`).
        wall_time : float, optional
            Passed to :meth:`markdown`.

        Returns
        -------
        str
            The HTML document; it loads nothing from the folder or the network.
        """
        import markdown as md_lib

        from .templates import HTML, environment

        text = self.markdown(wall_time=wall_time) if markdown is None else markdown
        conv = md_lib.Markdown(extensions=["tables", "fenced_code", "toc", "sane_lists"],
                               extension_configs={"toc": {"toc_depth": "2"}})
        body = typeset_html(text, conv.convert)  # formulas as SVG, typeset now
        body = _embed_images(body, Path(root))
        for word in ("yes", "no", "finding"):  # colour the verdicts' result cells
            body = body.replace(f"<td><strong>{word}</strong></td>",
                                f'<td class="{word}"><strong>{word}</strong></td>')
        return environment().from_string(HTML).render(title=self.title, body=body,
                                                     toc=getattr(conv, "toc", ""))

    def write(self, out: Any) -> list[str]:
        """Write ``report.md`` and ``report.html``.

        Parameters
        ----------
        out : OutputDir or path-like
            An open :class:`stringstab.io.OutputDir` (figures are read from its staging folder,
            the files staged with it) or a folder that holds the figures (files written
            atomically).

        Returns
        -------
        list of str
            The names written: ``["report.md", "report.html"]``.
        """
        from ..io import OutputDir, atomic_write_text

        wall = time.perf_counter() - self.started
        md = self.markdown(wall_time=wall)
        if isinstance(out, OutputDir):
            html = self.html(out.staging, markdown=md)
            out.write_text("report.md", md)
            out.write_text("report.html", html)
        else:
            folder = Path(out)
            html = self.html(folder, markdown=md)
            atomic_write_text(folder / "report.md", md)
            atomic_write_text(folder / "report.html", html)
        return ["report.md", "report.html"]


def _flush_verdicts(pending: list[dict[str, Any]], parts: list[str]) -> None:
    """Render the pending verdicts as one table into ``parts``; empty ``pending``."""
    if pending:
        rows = [f"| {_cell(v['what'])} | **{_mark(v['passed'])}** | {_cell(v['detail'])} |"
                for v in pending]
        parts.append("| what was checked | result | evidence |\n|---|---|---|\n" + "\n".join(rows))
        pending.clear()


def _mark(passed: bool | None) -> str:
    return {True: "yes", False: "no", None: "finding"}[passed]


def _duration(seconds: float) -> str:
    if seconds < 60:
        return f"{seconds:.1f} s"
    m, s = divmod(seconds, 60)
    return f"{int(m)} min {s:.0f} s"


_IMG = re.compile(r'(<img\b[^>]*?\bsrc=")([^"]+)(")')


def _embed_images(html: str, root: Path) -> str:
    """Replace the ``src`` of each local image by a base64 ``data:`` URI.

    A missing file is replaced by a visible note.
    """

    def repl(m: re.Match[str]) -> str:
        src = m.group(2)
        if src.startswith(("data:", "http:", "https:")):
            return m.group(0)
        p = root / src
        if not p.is_file():
            return m.group(1) + "data:," + m.group(3) + f' title="missing file: {src}"'
        mime = mimetypes.guess_type(p.name)[0] or "application/octet-stream"
        data = base64.b64encode(p.read_bytes()).decode("ascii")
        return f"{m.group(1)}data:{mime};base64,{data}{m.group(3)}"

    return _IMG.sub(repl, html)
