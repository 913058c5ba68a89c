"""The run report (stringstab.report): Markdown and a self-contained HTML from result objects."""

import base64
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pytest

from stringstab.cli import demo_steps as demo
from stringstab.cli import main
from stringstab.report import Report, caption_for


def _figure(path):
    fig, ax = plt.subplots(figsize=(2, 2))
    ax.plot([0, 1], [0, 1])
    fig.savefig(path, dpi=40)
    plt.close(fig)


def _embedded(html):
    """The bytes of every image embedded in an HTML page, and any non-data image source."""
    srcs = re.findall(r'<img\b[^>]*\bsrc="([^"]+)"', html)
    data = [base64.b64decode(s.split(",", 1)[1]) for s in srcs if s.startswith("data:image/")]
    other = [s for s in srcs if not s.startswith("data:image/")]
    return data, other


def test_report_markdown_and_html(tmp_path):
    _figure(tmp_path / "region_sup_gain.png")
    rep = Report("A run", command="stringstab region --fix k_a=0.5", params={"tau": 0.1},
                 version="9.9")
    sec = rep.section("Verdicts", "Some *text*.")
    sec.verdict("K string stable", True, "sup|Γ| = 0.93").verdict("other", False, "no")
    sec.table([{"k_x": 1.25, "verdict": "certified", "missing": None}], caption="Gains",
              units={"k_x": "s⁻²"})
    sec.figure("region_sup_gain.png")
    assert rep.write(tmp_path) == ["report.md", "report.html"]
    md = (tmp_path / "report.md").read_text(encoding="utf-8")
    for text in ("# A run", "`stringstab region --fix k_a=0.5`", "| stringstab version | 9.9 |",
                 "| K string stable | **yes** | sup\\|Γ\\| = 0.93 |", "| other | **no** | no |",
                 "*Table 1. Gains*", "| k_x (s⁻²) | verdict | missing |", "| 1.25 | certified | n/a |",
                 "![Figure 1](region_sup_gain.png)", "wall time"):
        assert text in md, text
    assert f"*Figure 1. {caption_for('region_sup_gain.png')}*" in md
    html = (tmp_path / "report.html").read_text(encoding="utf-8")
    data, other = _embedded(html)
    assert other == [] and data == [(tmp_path / "region_sup_gain.png").read_bytes()]
    assert "<table>" in html and "<strong>yes</strong>" in html
    assert not re.search(r'(src|href)="https?://', html)  # nothing loaded from the network


def test_markdown_block_headings_nest(tmp_path):
    rep = Report("T", command="c", version="0")
    rep.section("Results").markdown("# Title\n\n## Sub\n\n```\n# not a heading\n```\n", shift=2)
    md = rep.markdown(wall_time=0.0)
    assert "### Title" in md and "#### Sub" in md and "\n# not a heading" in md


#: Source that must never show in a rendered report: TeX commands, dollars, TeX's braced sub- and
#: superscripts, SymPy's powers and products (``k_a*s**2*exp(-delta*s)``).
RAW_SOURCE = re.compile(r"\\[A-Za-z]{2,}|\$|[_^]\{|\*\*|\b[a-z]\w*\*[a-z(]|\bexp\(")


def _rendered(html):
    """Lay the page out with WeasyPrint (a real HTML/CSS engine): the images it drew with a
    non-zero natural size, the number of <img> tags, the text a reader sees, and its warnings."""
    import logging

    try:
        import weasyprint
        from weasyprint.formatting_structure import boxes
    except (ImportError, OSError) as e:  # OSError: the system's Pango is missing
        pytest.skip(f"WeasyPrint (the 'test' extra, with the system's Pango) is needed to render "
                    f"the report: {e}")
    records = []

    class Keep(logging.Handler):
        def emit(self, record):
            records.append(record.getMessage())

    handler = Keep(level=logging.WARNING)
    logging.getLogger("weasyprint").addHandler(handler)
    try:
        doc = weasyprint.HTML(string=html).render()
    finally:
        logging.getLogger("weasyprint").removeHandler(handler)

    def walk(box):
        yield box
        for child in getattr(box, "children", None) or []:
            yield from walk(child)

    drawn, texts = [], []
    for page in doc.pages:
        for box in walk(page._page_box):
            if isinstance(box, boxes.ReplacedBox):
                w, h, _ = box.replacement.get_intrinsic_size(1, 16)
                drawn.append((w or 0) > 0 and (h or 0) > 0 and box.width > 0 and box.height > 0)
            elif isinstance(box, boxes.TextBox):
                texts.append(box.text)
    n_img = len(re.findall(r"<img\b", html))
    return drawn, n_img, " ".join(texts), [m for m in records if "image" in m.lower()]


def _assert_reads_well(html):
    drawn, n_img, text, failures = _rendered(html)
    assert failures == [], failures  # no image failed to load
    assert len(drawn) == n_img and all(drawn), (len(drawn), n_img)  # every <img> drawn, sized
    raw = sorted({m.group(0) for m in RAW_SOURCE.finditer(text)})
    assert not raw, f"raw TeX/SymPy source in the rendered text: {raw}"
    return text


def test_the_render_check_can_fail():
    """The check catches a broken figure, a formula left as TeX and SymPy source."""
    html = ('<p>Γ(s) = k_a*s**2*exp(-delta*s) and $\\Gamma$ and a_{i-1}</p>'
            '<img alt="fig" src="data:image/png;base64,AAAA">')
    drawn, n_img, text, failures = _rendered(html)
    assert failures and len(drawn) < n_img
    assert {m.group(0) for m in RAW_SOURCE.finditer(text)} >= {"**", "$", "\\Gamma", "_{",
                                                                "exp(", "k_a*s"}


def test_demo_writes_the_report(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--only", "derive", "--only", "certify",
                 "--only", "tune"]) == 0
    md = (out / "report.md").read_text(encoding="utf-8")
    assert "## The findings at a glance" in md
    assert "| the paper's printed formulas match the model | **no** |" in md
    assert "eq 11 (denominator of Γ(s))" in md and "Proposition 1 (logic)" in md
    assert "(proposition1)" not in md and "triple(s)" not in md
    assert "0.9, -0.5, 1.1" in md  # the triple the printed Proposition 1 misjudges
    assert "certified_row_share = 0.771" in md and "m_fss = 0.771" not in md
    assert "$$\\Gamma(s) = \\frac{" in md  # Γ(s) as TeX, typeset in the HTML
    assert "tune/tune_moves.png" in md and "`stringstab demo (called from Python with" in md
    html = (out / "report.html").read_text(encoding="utf-8")
    data, other = _embedded(html)
    figures = [d for d in data if d.startswith(b"\x89PNG")]
    formulas = [d for d in data if d.startswith(b"<?xml")]
    assert other == [] and figures == [(out / "tune" / "tune_moves.png").read_bytes()]
    assert len(formulas) >= 10 and all(b"<svg" in f for f in formulas)
    assert not re.search(r'(src|href)="https?://', html)  # nothing loaded from the network
    assert "report.html" in capsys.readouterr().out
    text = _assert_reads_well(html)
    assert "Γ(s) =" not in text  # the formula is an image, not SymPy text
    # a repair the exact certificate does not certify is never called "repaired"
    rows = [line for line in md.splitlines() if line.startswith("| region-growing |")]
    assert rows and all(("| no | repaired |" not in r) for r in rows)
    assert any("| no | moved_not_certified |" in r for r in rows)


def test_region_command_report(tmp_path, capsys):
    out = tmp_path / "maps"
    assert main(["region", "--fix", "k_a=0.5", "--n", "11", "--out", str(out), "--no-progress"]) == 0
    md = (out / "report.md").read_text(encoding="utf-8")
    pngs = sorted(p.name for p in out.glob("*.png"))
    assert pngs and all(f"]({p})" in md for p in pngs)
    # and no other: the figures not drawn by default (issue 31) are not referenced
    assert "class_taylor" not in md and "class_printed" not in md
    assert md.count(".png)") == len(pngs)
    html = (out / "report.html").read_text(encoding="utf-8")
    data, other = _embedded(html)
    assert other == [] and sorted(data) == sorted((out / p).read_bytes() for p in pngs)
    assert "exact vs taylor agree on every decided point" in md
    _assert_reads_well(html)


@pytest.mark.parametrize("name", ["region_class_exact.png", "platoon.png", "fig9_ttc.png", "fit_1.png",
                                  "transfer_2_3.png", "sup_gain.png",
                                  "jerk_1-us06_J2.5.png"])
def test_every_figure_kind_has_a_caption(name):
    assert not caption_for(name).startswith("Figure ")


def test_demo_steps_have_report_sections():
    from stringstab.report.demo import demo_report

    rep = demo_report({}, ".", command="stringstab demo")
    assert [s.title for s in rep.sections] == ["The findings at a glance", "Run time per step"]
    assert {n for n, _ in demo.STEPS} >= {"derive", "certify", "region", "tune", "simulate",
                                          "hcfs", "train"}


def test_comparison_table_states_what_it_used_to_hide():
    from stringstab.rl.compare import table_markdown, table_rows

    summaries = {"idl": {"TIT": 0.294, "M_CI": 0.79, "M_effi": 2.04, "M_lss": 0.875,
                         "m_fss": 1.0, "share_m_p_below_1": 1.0},
                 "cacc": {"TIT": 0.0, "M_CI": 1.91, "M_effi": 2.75, "M_lss": 0.975,
                          "m_fss": None, "share_m_p_below_1": 0.7857}}
    md = table_markdown(table_rows(summaries, "idl"))
    lines = {line.split(" | ")[0].strip("| "): line for line in md.splitlines()}
    assert "m_fss (fraction, ↑)" in lines["strategy"] and "TIT (s², ↓)" in lines["strategy"]
    assert "| 1 |" in lines["idl"]  # the fraction, as written
    assert "0 (no certified gains executed)" in lines["cacc"]  # not "–"
    assert "m_p > 1 in 21% of episodes" in lines["cacc"] and "stable" not in lines["cacc"]
    assert "m_p < 1 in every episode" in lines["idl"]
    # TIT: CACC's is 0, so the percentage is undefined; the row says IDL is worse
    assert "worse: 0.294 vs 0" in lines["idl compared to cacc"]
    assert "+58." in lines["idl compared to cacc"]  # M_CI: 100 (1.91 − 0.79)/1.91


def test_evaluation_table_has_names_and_units():
    from stringstab.rl.report import EVALUATION_METRICS

    assert EVALUATION_METRICS["TIT"][1] == "s²" and EVALUATION_METRICS["M_CI"][1] == "m²/s⁶"
    assert all(unit for _, unit in EVALUATION_METRICS.values())


def test_tune_report(tmp_path, capsys):
    out = tmp_path / "rep"
    assert main(["tune", "0.9,-0.5,1.1", "--method", "projection", "--report", str(out)]) == 0
    md = (out / "report.md").read_text(encoding="utf-8")
    assert "| every output certified | **yes** | 1 of 1 certified |" in md
    data, other = _embedded((out / "report.html").read_text(encoding="utf-8"))
    assert other == [] and data == [(out / "tune_moves.png").read_bytes()]
