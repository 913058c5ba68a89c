"""One way in to the certificates (issue 32, item 2): no side door around ``certify.api``.

A *side door* is a public function of a ``stringstab.certify`` module other than ``api``, named
``certify*`` or ``check*``, that takes unchecked gains (a parameter ``k_x``; the kernels behind
the way in take checked arrays ``kx``) and returns a certificate or a check (its return
annotation names a ``...Certificate``, ``...CertificateBatch`` or ``...Check``): it would check
the inputs a second time, in its own words, beside :mod:`stringstab.certify.api`.  The rule is
the one ``analysis/house_figures.py`` counts.
"""

from __future__ import annotations

import ast
import re

from .test_house import MODULES

RESULT = re.compile(r"(Certificate|CertificateBatch|Check)\b")


def side_doors(sources: dict[str, str]) -> list[str]:
    """``module.function`` of every side door among ``sources`` (module name → source)."""
    out = []
    for mod, text in sorted(sources.items()):
        if not mod.startswith("stringstab.certify.") or mod == "stringstab.certify.api":
            continue
        for node in ast.parse(text).body:
            if (isinstance(node, ast.FunctionDef) and not node.name.startswith("_")
                    and node.name.startswith(("certify", "check"))
                    and "k_x" in [a.arg for a in (*node.args.args, *node.args.kwonlyargs)]
                    and node.returns is not None and RESULT.search(ast.unparse(node.returns))):
                out.append(f"{mod}.{node.name}")
    return out


def _sources() -> dict[str, str]:
    return {mod: path.read_text(encoding="utf-8") for mod, path in MODULES.items()}


def test_no_side_door_around_the_way_in():
    assert side_doors(_sources()) == []


def test_the_side_door_check_can_fail():
    sources = _sources()
    # a planted wrapper of the sampled kernel, as check_sampled was; and what is not a door:
    # the kernel's own form (checked arrays kx), a private helper, and the way in itself
    sources["stringstab.certify.sampled"] += (
        "\n\ndef check_planted(k_x, k_v, k_a, *, tau, delta, headway, sample_time) -> SampledCheck:"
        "\n    ...\n"
        "\n\ndef check_kernel_planted(kx, kv, ka, p, H, tp) -> SampledCheck:\n    ...\n"
        "\n\ndef _certify_planted(k_x, k_v, k_a) -> SampledCertificateBatch:\n    ...\n")
    assert side_doors(sources) == ["stringstab.certify.sampled.check_planted"]
    assert "stringstab.certify.api" in sources  # api's certify/check take k_x and are no door
