r"""Maths typeset at build time: TeX in ``$…$`` / ``$$…$$`` rendered to SVG by matplotlib's mathtext.

The report's Markdown keeps the TeX (``$\Gamma(s)$``; GitHub and most Markdown viewers typeset
it); the HTML page gets each formula as an SVG image embedded as a ``data:`` URI, drawn by
matplotlib's own TeX subset (:mod:`matplotlib.mathtext`, Computer Modern fonts shipped with
matplotlib, glyphs as paths). Nothing is loaded at reading time: no script, no font, no
network, and the page stays one file. The same renderer typesets the ``.. math::`` blocks of the
docstrings on the documentation site (``docs/griffe_rst.py``).

Only mathtext's subset of TeX is available (fractions, sub/superscripts, Greek, ``\left(``,
``\sup``, ``\Vert``, ``\mathcal``…); environments such as ``align`` are not.  A formula it
cannot parse raises :class:`~stringstab.errors.StringStabError` naming the formula.
"""

from __future__ import annotations

import base64
import html
import re
from dataclasses import dataclass
from functools import lru_cache

__all__ = ["MATH", "Formula", "inline_tex", "mathtext_tex", "split_maths", "typeset", "typeset_html"]

#: Inline ``$x$`` (no space inside the dollars, as pandoc reads them) or display ``$$x$$``.
MATH = re.compile(r"\$\$(?P<display>.+?)\$\$|(?<![\\$\w])\$(?P<inline>[^\s$](?:[^$\n]*?[^\s$\\])?)\$(?![\w$])",
                  re.DOTALL)

_CODE = re.compile(r"(```.*?```|`[^`\n]+`)", re.DOTALL)
#: A word written with TeX's braced sub- or superscripts (``e^{-δs}``, ``a_{i−1}``).
_BRACED = re.compile(r"(?<![\w$\\])([^\s$(){}\[\],;]*?[_^]\{[^{}$]*\}(?:[_^]\{[^{}$]*\})*)")


@dataclass(frozen=True)
class Formula:
    """One typeset formula: its SVG and its size, in points.

    Attributes
    ----------
    tex : str
        The TeX source (mathtext's subset), without the dollars.
    svg : bytes
        The SVG document (glyphs as paths: no font needed to show it).
    width, height, depth : float
        The box in points; ``depth`` is how far the baseline sits above the bottom, so the image
        aligns with the text around it when shifted down by it.
    display : bool
        A display formula (its own line, centred) rather than an inline one.
    """

    tex: str
    svg: bytes
    width: float
    height: float
    depth: float
    display: bool

    def img(self) -> str:
        """The ``<img>`` tag that shows the formula (a ``data:`` URI; alt text the TeX).

        Returns
        -------
        str
            HTML.
        """
        data = base64.b64encode(self.svg).decode("ascii")
        cls = "math display" if self.display else "math"
        style = (f"width:{self.width:.2f}pt;height:{self.height:.2f}pt;"
                 f"vertical-align:{-self.depth:.2f}pt")
        return (f'<img class="{cls}" alt="{html.escape(self.tex, quote=True)}" style="{style}" '
                f'src="data:image/svg+xml;base64,{data}">')


#: TeX that mathtext does not know, and what it does know that draws the same.
_COMPAT = [(re.compile(p), r) for p, r in (
    (r"\\ge(?![a-zA-Z])", r"\\geq"), (r"\\le(?![a-zA-Z])", r"\\leq"),
    (r"\\ne(?![a-zA-Z])", r"\\neq"),
    (r"\\(?:text|textrm|operatorname)\{", r"\\mathrm{"), (r"\\[dt]frac", r"\\frac"),
    (r"\\lvert|\\rvert", "|"), (r"\\lVert|\\rVert", r"\\Vert "),
    (r"\\(?:big|Big|bigg|Bigg)[lr]?(?![a-zA-Z])", ""), (r"\\displaystyle", ""),
    (r"\\limits", ""), (r"\\!", ""),
)]


def mathtext_tex(tex: str) -> str:
    r"""The formula in mathtext's dialect of TeX (``\ge`` → ``\geq``, ``\text`` → ``\mathrm``…).

    Parameters
    ----------
    tex : str
        TeX as written in a docstring or a report.

    Returns
    -------
    str
        The same formula, in commands mathtext knows.

    Examples
    --------
    >>> mathtext_tex(r"g \ge 0, \text{if } \tfrac{a}{b} \le 1")
    'g \\geq 0, \\mathrm{if } \\frac{a}{b} \\leq 1'
    """
    for pattern, repl in _COMPAT:
        tex = pattern.sub(repl, tex)
    return tex


@lru_cache(maxsize=512)
def typeset(tex: str, *, display: bool = False, size: float = 13.5) -> Formula:
    r"""Render one formula to SVG with matplotlib's mathtext (Computer Modern).

    Parameters
    ----------
    tex : str
        The formula without dollars, e.g. ``r"\Vert\Gamma\Vert_{\mathcal{H}_\infty} \leq 1"``.
    display : bool, optional
        A display formula (drawn 40 % larger: mathtext sets fractions small; on its own line).
    size : float, optional
        Font size of an inline formula, points (the report's text is 12 pt; Computer Modern
        reads smaller than its sans-serif at one size).

    Returns
    -------
    Formula
        The SVG and its box.

    Raises
    ------
    StringStabError
        If mathtext cannot parse the formula.

    Examples
    --------
    >>> f = typeset(r"\frac{k_a s^2 e^{-\delta s}}{D(s)}")
    >>> f.svg.startswith(b"<?xml") and f.height > f.depth > 0 and f.width > 20
    True
    """
    import io

    import matplotlib
    from matplotlib.backends.backend_svg import FigureCanvasSVG
    from matplotlib.figure import Figure
    from matplotlib.font_manager import FontProperties
    from matplotlib.mathtext import MathTextParser

    from ..errors import StringStabError

    src = mathtext_tex(tex)
    pts = size * (1.4 if display else 1.0)
    with matplotlib.rc_context({"mathtext.fontset": "cm", "svg.fonttype": "path",
                                "svg.hashsalt": "stringstab"}):
        prop = FontProperties(size=pts)
        try:
            box = MathTextParser("path").parse(f"${src}$", dpi=72, prop=prop)
        except ValueError as e:
            raise StringStabError(f"cannot typeset the formula ${tex}$ with matplotlib's mathtext: "
                                  f"{str(e).splitlines()[-1]}") from e
        width, height, depth = float(box[0]), float(box[1]), float(box[2])
        pad = 1.0  # points around the ink, so no glyph touches the edge
        fig = Figure(figsize=((width + 2 * pad) / 72.0, (height + 2 * pad) / 72.0))
        FigureCanvasSVG(fig)
        fig.text(pad / (width + 2 * pad), (depth + pad) / (height + 2 * pad), f"${src}$",
                 fontproperties=prop)
        buf = io.BytesIO()
        fig.savefig(buf, format="svg", dpi=72, transparent=True, metadata={"Date": None})
    return Formula(tex, buf.getvalue(), width + 2 * pad, height + 2 * pad, depth + pad, display)


def inline_tex(text: str) -> str:
    """Mark the words of plain text written in TeX (``e^{-δs}``, ``a_{i−1}``) as formulas.

    Text written elsewhere in the toolkit (an erratum's explanation) uses TeX's braces for
    sub- and superscripts; wrapped in dollars they are typeset instead of shown as source.

    Parameters
    ----------
    text : str
        Plain text.

    Returns
    -------
    str
        The text with each such word in ``$…$``.

    Examples
    --------
    >>> inline_tex("with e^{-δs} replaced; k_x stays")
    'with $e^{-δs}$ replaced; k_x stays'
    """
    return _BRACED.sub(lambda m: f"${m.group(1)}$", text)


def split_maths(text: str) -> list[tuple[str, str | None, bool]]:
    """Split Markdown into plain runs and formulas, leaving code spans and fenced code alone.

    Parameters
    ----------
    text : str
        Markdown with ``$…$`` (inline) and ``$$…$$`` (display) formulas.

    Returns
    -------
    list of (str, str or None, bool)
        ``(plain, None, False)`` for text, ``(source, tex, display)`` for a formula (``source``
        with its dollars).

    Examples
    --------
    >>> [p for p in split_maths("cost $5 and $x_1$, `echo $HOME`") if p[1]]
    [('$x_1$', 'x_1', False)]
    """
    out: list[tuple[str, str | None, bool]] = []
    for k, chunk in enumerate(_CODE.split(text)):
        if k % 2:  # code: kept verbatim
            out.append((chunk, None, False))
            continue
        pos = 0
        for m in MATH.finditer(chunk):
            out.append((chunk[pos:m.start()], None, False))
            disp = m.group("display") is not None
            out.append((m.group(0), (m.group("display") if disp else m.group("inline")).strip(), disp))
            pos = m.end()
        out.append((chunk[pos:], None, False))
    return [p for p in out if p[0]]


def typeset_html(markdown_text: str, convert: object) -> str:
    """Convert Markdown to HTML with every formula typeset as an embedded SVG image.

    Formulas are cut out before the conversion (so ``_`` and ``*`` in them are not emphasis) and
    put back as ``<img>`` tags after it.

    Parameters
    ----------
    markdown_text : str
        The Markdown.
    convert : callable
        Markdown to HTML (e.g. ``markdown.Markdown(...).convert``).

    Returns
    -------
    str
        The HTML.

    Examples
    --------
    >>> import markdown
    >>> out = typeset_html("a $k_a$ b", markdown.markdown)
    >>> out.startswith('<p>a <img class="math" alt="k_a"') and out.endswith(" b</p>")
    True
    """
    parts = split_maths(markdown_text)
    imgs: dict[str, str] = {}
    pieces = []
    for source, tex, display in parts:
        if tex is None:
            pieces.append(source)
            continue
        key = f"STRINGSTABMATH{len(imgs):05d}X"
        imgs[key] = typeset(tex, display=display).img()
        pieces.append(f"\n\n{key}\n\n" if display else key)
    out = str(convert("".join(pieces)))  # type: ignore[operator]
    for key, tag in imgs.items():
        out = out.replace(f"<p>{key}</p>", f'<p class="math">{tag}</p>').replace(key, tag)
    return out
