"""The report's two Jinja2 templates: the Markdown document and the HTML page around it."""

from __future__ import annotations

from functools import lru_cache
from typing import Any

__all__ = ["HTML", "MARKDOWN", "environment"]

#: The Markdown document: title, what was run, then each section's rendered blocks.
MARKDOWN = """\
# {{ title }}

{% if intro %}{{ intro }}

{% endif -%}
| run | |
|---|---|
| command | `{{ command }}` |
| stringstab version | {{ version }} |
| date | {{ date }} |
| wall time | {{ wall }} |
{% for k, v in params %}| {{ k }} | {{ v | cell }} |
{% endfor %}
{% for s in sections %}
## {{ s.title }}

{% for p in s.parts %}{{ p }}

{% endfor %}{% endfor %}
"""

#: The HTML page: inline CSS, a contents list, the converted Markdown (formulas already typeset as
#: embedded SVG images, :mod:`stringstab.report.maths`); nothing loaded from outside.
HTML = """\
<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="stringstab">
<title>{{ title | e }}</title>
<style>
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, "DejaVu Sans", sans-serif;
       max-width: 64rem; margin: 2rem auto; padding: 0 1.2rem; line-height: 1.5; color: #1b1b1b; }
h1 { border-bottom: 2px solid #3f51b5; padding-bottom: .3rem; }
h2 { border-bottom: 1px solid #ccc; padding-bottom: .2rem; margin-top: 2.4rem; }
table { border-collapse: collapse; margin: .6rem 0 1.2rem; font-size: .92rem; display: block;
        max-width: 100%; overflow-x: auto; }
th, td { border: 1px solid #c8c8c8; padding: .25rem .55rem; text-align: left; vertical-align: top; }
th { background: #eef0f8; }
tr:nth-child(even) td { background: #fafafa; }
code, pre { font-family: ui-monospace, "DejaVu Sans Mono", monospace; font-size: .88rem; }
pre { background: #f5f5f5; padding: .6rem; overflow-x: auto; }
img { max-width: 100%; height: auto; display: block; margin: 1rem auto .3rem;
      border: 1px solid #e3e3e3; }
img.math { display: inline; margin: 0; border: 0; max-width: none; }
p.math { text-align: center; margin: .8rem 0; }
p > em:only-child { color: #444; }
td.yes { background: #e6f4ea !important; color: #1b5e20; }
td.no { background: #fde8e8 !important; color: #b71c1c; }
td.finding { background: #eef3fb !important; color: #1a3e72; }
nav.toc { background: #f7f7fb; border: 1px solid #dde; padding: .4rem 1rem; font-size: .92rem; }
nav.toc ul { margin: .2rem 0; }
</style>
</head>
<body>
<nav class="toc"><strong>Contents</strong>{{ toc }}</nav>
{{ body }}
</body>
</html>
"""


def _cell(v: Any) -> str:
    return str(v).replace("|", "\\|").replace("\n", " ")


@lru_cache(maxsize=1)
def environment() -> Any:
    """The Jinja2 environment of the templates, with a ``cell`` filter escaping table cells.

    No autoescaping: the Markdown is escaped by the converter.

    Returns
    -------
    jinja2.Environment
        The shared environment.
    """
    import jinja2

    env = jinja2.Environment(autoescape=False, keep_trailing_newline=True,
                             undefined=jinja2.StrictUndefined)
    env.filters["cell"] = _cell
    return env
