"""Every `stringstab ...` example of README.md and docs/*.md works from a fresh clone.

The examples are the `$ stringstab ...` lines of their code blocks (and the `stringstab`
commands of the README's and quickstart's setup lines), split at `&&`, with `> FILE` taken as
the output.  Each is checked three ways:

(a) every file it reads is in the repository (a file git tracks, relative to the clone's root),
    or is written by another documented example (its `--out`, or `> FILE`), or is listed in
    PLACEHOLDERS: a name that stands for the reader's own file, with the reason;
(b) the real argument parser (`stringstab.cli.build_parser`) accepts it: no unknown flag, no
    bad choice;
(c) it runs, in a temporary folder laid out as the clone (its tracked top-level folders linked
    in), outputs there: exit 0 or 1 (1 is a verdict: "not certified", a collision), or, where
    the docs show the error it prints, exit 2 with exactly that line; a warning the docs show
    is printed too.  A long example runs with a budget shrunk by the documented options in
    SHRINK (each with its reason; nothing else changes) or is listed in NOT_RUN with the reason
    and where its code is tested instead.  A command is never skipped silently: the test fails
    on an example that is neither run nor listed, and on a list entry that no longer matches
    any example.  An example whose optional extra is not installed (EXTRAS) is not run, and
    the test then reports itself skipped, naming it.

`region` runs as a subprocess (it forks to write its figures; pytest's process has threads);
the others run in this process through `stringstab.cli.main`.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import importlib.util
import io
import os
import re
import shlex
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from stringstab.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[2]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

#: Names in the docs that stand for the reader's own file (not shipped), with the reason.
PLACEHOLDERS: dict[str, str] = {
    "big.npz": "a large gain file of the reader's (any .npz of triples; the format is described "
               "beside it)",
    "gains.npz": "the reader's gain file in NPZ (format described in docs/certify.md)",
    "gains.csv": "the reader's gain time series (format described in docs/simulate.md)",
    "my_leader.csv": "the reader's own leader profile 't, v' (format described beside it)",
    "platoon.csv": "the reader's own log with acceleration columns, which --model cacc needs and "
                   "the shipped OpenACC logs lack",
    "rollout.csv": "docs/certify.md's example of a malformed file (its documented error line); "
                   "the refusals are tested in tests/io/test_gain_files.py",
    "typo.csv": "docs/certify.md's example of a misspelt column (tests/io/test_gain_files.py)",
    "bad.toml": "docs/sweeps.md's example of a spec with an unknown field "
                "(tests/sweep/test_sweep_spec.py)",
    "bad2.toml": "docs/sweeps.md's example of a spec with a bad value (tests/sweep/test_sweep_spec.py)",
    "bad3.toml": "docs/sweeps.md's example of an empty axis (tests/sweep/test_sweep_spec.py)",
    "big.toml": "docs/sweeps.md's example of a spec whose certify point (n = 100000) no worker "
                "can hold; the numbers in its error line depend on the machine's memory "
                "(tests/cli/test_cli_inputs.py refuses such a sweep before dispatch)",
}

#: Examples not run, by the start of the command (after `stringstab`), with the reason.
NOT_RUN: dict[str, str] = {
    "train ": "trains a policy (300,000 steps; even 64 steps with the torch import is ~9 s CPU); "
              "tests/rl/test_rl.py and tests/demo/test_demo_train.py train with tiny budgets",
    "evaluate ": "needs a trained run folder (train is not run here) and rolls every test "
                 "episode (~80 s); tests/rl/test_rl.py evaluates a tiny run",
    "compare ": "needs three trained run folders; tests/rl/test_rl.py compares tiny runs",
    "hcfs train ": "trains the HCFS DDPG (400,000 steps); tests/hcfs/test_hcfs_ddpg.py trains briefly",
    "hcfs verify -J 2.5 --leader hcfs-case1 --policy runs/hcfs-ddpg": "needs the policy of "
        "`hcfs train` (not run); tests/cli/test_cli_hcfs.py verifies with the bundled policy",
    "sumo run --leader udds --policy runs/idl": "needs the policy of `train` (not run); "
        "tests/sumo/test_sumo_policy.py drives SUMO with a tiny trained policy",
    "certify --file runs/idl/evaluation/gains.csv": "needs the gains `evaluate` writes (not "
        "run); certify --file is run on the shipped rollout",
    "sweep analysis/sweeps/smoke.toml": "starts a Dask cluster and trains (about a minute); "
        "tests/sweep/test_sweep_run.py runs sweeps of tiny specs",
    "sweep analysis/sweeps/table3": "hours of training on a cluster (the paper's study); "
        "`--check` of a spec is run",
    "sweep analysis/sweeps/table5": "hours of training (the paper's study)",
    "sweep analysis/sweeps/fig5_reduced.toml --out runs/": "hours of training (the paper's study)",
    "sweep analysis/sweeps/fig4": "hours of training (the paper's study)",
    "sweep analysis/sweeps/certificate": "minutes of certificates on a local cluster; "
        "tests/sweep/test_sweep_run.py runs tiny sweeps on one",
    "demo ": "the whole pipeline, a few minutes; tests/demo/test_demo*.py run its steps",
    "platoon simulate ": "designs a CAV and replays ~550 s of the recorded leader twice and a "
        "probe (~30 s of CPU, minutes under load); tests/mixed/test_platoon_cli.py runs the design and "
        "the probe on small strings",
    "platoon design --from runs/acc/identify.json --cav-at auto": "designs every position and "
        "pair of the string (minutes); tests/mixed/test_platoon_cli.py runs single designs",
    "platoon design --from runs/acc/identify.json --cav-at 1": "a full design search (bisection "
        "of NLPs, ~20 s of CPU, a minute under load); the quick `--cav-at 5` example runs, and "
        "tests/mixed/test_platoon_cli.py runs certified designs on small strings",
}


def _set(argv: list[str], flag: str, value: str | None) -> list[str]:
    """``argv`` with ``flag`` set to ``value`` (added, or its value replaced); value None: a switch."""
    out = list(argv)
    if flag in out:
        if value is not None:
            out[out.index(flag) + 1] = value
        return out
    return [*out, flag] if value is None else [*out, flag, value]


#: Budget shrinks: (start of the command, the change, why it only shrinks the budget).
SHRINK: list[tuple[str, Callable[[list[str]], list[str]], str]] = [
    ("identify ", lambda a: _set(_set(_set(a, "--bootstrap", "0"), "--starts", "1"),
                                 "--no-figures", None),
     "no bootstrap refits, one starting point, no figures: the same reading, fit and "
     "certificate (50 refits x 4 starts take minutes; the bootstrap and figures are tested in "
     "tests/identify/test_identify*.py)"),
    ("region ", lambda a: _set(_set(_set(a, "--n", "5" if "--3d" in a else "11"), "--format", "png"),
                               "--no-progress", None),
     "an 11-point grid (5 in 3-D) instead of 201-801, figures in PNG only (the PDF/SVG are the "
     "same figures; tests/cli/test_cli_region.py writes them): the grid size and formats only"),
    ("sumo check ", lambda a: _set(a, "--duration", "30"),
     "the first 30 s of the leader (the whole UDDS is 1369 s)"),
    ("sumo run --leader", lambda a: _set(_set(a, "--duration", "30"), "--no-figures", None),
     "the first 30 s of the leader, no figures (tests/sumo/test_sumo.py writes them)"),
    ("sumo cacc ", lambda a: _set(a, "--duration", "30"), "30 s of the leader instead of 300"),
    ("sumo run --sumocfg", lambda a: _set(a, "--steps", "300"), "the first 300 steps (30 s)"),
    ("hcfs verify ", lambda a: _set(_set(a, "--duration", "20"), "--no-figures", None),
     "20 s of each leader, no figures (tests/hcfs/test_hcfs_closed_loop.py writes them)"),
    ("radio ", lambda a: _set(_set(_set(_set(_set(_set(a, "--seeds", "2"), "--loss", "0,0.1"),
                                             "--burst", "1"), "--duration", "20"), "--hold", "0"),
                              "--followers", "3"),
     "2 seeds, loss 0 and 0.1 (independent), 20 s of the leader (a leader under 10 s or the "
     "CACC's settling time, 10.4 s here, is refused), 3 followers: the same command "
     "on a grid of 2 points instead of 14 x 20 runs of 10 followers (minutes; "
     "tests/traffic/test_radio_study.py runs the study and checks its numbers)"),
    ("simulate ", lambda a: _set(_set(a, "--no-figures", None), "--duration", "200"),
     "the first 200 s of the leader, no figures (tests/cli/test_cli_simulate.py and "
     "tests/plots/test_figures.py draw them)"),
]

#: Examples that need an optional extra: (start of the command, a module of it, the extra).
#: Without it they are not run and the test reports itself skipped, naming them.
EXTRAS: list[tuple[str, str, str]] = [
    ("sumo ", "libsumo", "sumo"),
    ("hcfs verify ", "torch", "rl"),  # the bundled DDPG policy
]

#: Options whose value is written, not read.
OUTPUT_DESTS = {"out", "prefix", "json"}
#: What looks like a file path among the values of the other options.
PATHLIKE = re.compile(r"\.(csv|json|npz|parquet|toml|xml|sumocfg|gz|txt)$|/")


@dataclass
class Example:
    doc: str
    line: int
    argv: list[str]
    stdout_to: str | None = None
    shown: list[str] = field(default_factory=list)  # lines the docs show it printing

    @property
    def where(self) -> str:
        return f"{self.doc}:{self.line}: stringstab {shlex.join(self.argv)}"

    @property
    def text(self) -> str:
        return shlex.join(self.argv) + " "


def _commands(text: str) -> list[tuple[list[str], str | None]]:
    """The ``stringstab`` commands of a shell line (split at ``&&``), each with its ``> FILE``."""
    try:
        tokens = shlex.split(text, comments=True)
    except ValueError:
        return []
    out, cur = [], []
    for tok in [*tokens, "&&"]:
        if tok != "&&":
            cur.append(tok)
            continue
        if cur and Path(cur[0]).name == "stringstab":
            argv, to = cur[1:], None
            if ">" in argv:
                k = argv.index(">")
                argv, to = argv[:k], argv[k + 1]
            out.append((argv, to))
        cur = []
    return out


def examples() -> list[Example]:
    found: list[Example] = []
    for doc in DOCS:
        name = str(doc.relative_to(ROOT))
        fence = None
        last: list[Example] = []
        for n, line in enumerate(doc.read_text(encoding="utf-8").splitlines(), start=1):
            s = line.strip()
            if s.startswith("```"):
                fence = None if fence is not None else s[3:].strip()
                last = []
                continue
            if fence is None:
                continue
            if s.startswith("$ "):
                last = [Example(name, n, a, to) for a, to in _commands(s[2:])]
                found += last
            elif fence == "bash" and "stringstab" in s:
                found += [Example(name, n, a, to) for a, to in _commands(s)]
            elif last and s.startswith("stringstab "):
                last[-1].shown.append(s)
    return found


EXAMPLES = examples()


def _parse(ex: Example):
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        try:
            return build_parser().parse_args(ex.argv)
        except SystemExit:
            pytest.fail(f"{ex.where}: the parser refuses it: {err.getvalue().strip()}")


@functools.cache
def _parsed() -> list[tuple[Example, argparse.Namespace]]:
    """Every example with its parsed command line (the real parser)."""
    return [(ex, _parse(ex)) for ex in EXAMPLES]


def _reads(ns) -> list[str]:
    paths = []
    for key, value in vars(ns).items():
        if key in OUTPUT_DESTS or key == "func":
            continue
        for v in value if isinstance(value, list) else [value]:
            if not isinstance(v, str) or "://" in v:
                continue
            if ":" in v and v.split(":")[0].endswith(".xml"):  # --vtype FILE:TYPE
                v = v.split(":")[0]
            if PATHLIKE.search(v):
                paths.append(os.path.normpath(v))
    return paths


def _writes(ex: Example, ns) -> list[str]:
    out = [os.path.normpath(ex.stdout_to)] if ex.stdout_to else []
    if isinstance(getattr(ns, "out", None), str):
        out.append(os.path.normpath(ns.out))
    elif ns.command == "evaluate":
        out.append(os.path.normpath(os.path.join(ns.run, "evaluation")))
    return out


@functools.cache
def _tracked() -> set[str]:
    try:
        files = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True,
                               check=True, timeout=60).stdout.split()
    except (OSError, subprocess.SubprocessError):  # not a clone: what is on disk
        files = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*") if p.is_file()
                 and ".venv" not in p.parts and ".git" not in p.parts]
    out = set(files)
    for f in files:
        out.update(str(p) for p in Path(f).parents if str(p) != ".")
    return out


def _producer(path: str, table: list[tuple[Example, list[str]]]) -> Example | None:
    for ex, written in table:
        if any(path == w or path.startswith(w + os.sep) for w in written):
            return ex
    return None


def _shrunk(ex: Example) -> tuple[list[str], str | None]:
    for start, change, why in SHRINK:
        if ex.text.startswith(start):
            return change(ex.argv), why
    return ex.argv, None


def _not_run(ex: Example) -> str | None:
    return next((why for start, why in NOT_RUN.items() if ex.text.startswith(start)), None)


def test_examples_are_found() -> None:
    assert len(EXAMPLES) > 80
    texts = [e.text for e in EXAMPLES]
    assert any(t.startswith("identify --example acc") for t in texts)
    assert any(t.startswith("demo --out demo-out") for t in texts)  # the README's setup line
    shown = [e for e in EXAMPLES if e.shown]
    assert any("error:" in s for e in shown for s in e.shown)


def test_every_example_parses_and_reads_only_what_a_clone_has() -> None:
    tracked = _tracked()
    parsed = _parsed()
    table = [(ex, _writes(ex, ns)) for ex, ns in parsed]
    used = set()
    missing = []
    for ex, ns in parsed:
        for path in _reads(ns):
            if path in tracked or _producer(path, table) is not None:
                continue
            if path in PLACEHOLDERS:
                used.add(path)
                continue
            missing.append(f"{ex.where}: reads {path!r}, which a fresh clone does not have")
    assert not missing, "\n".join(missing)
    assert used == set(PLACEHOLDERS), f"stale PLACEHOLDERS: {set(PLACEHOLDERS) - used}"


def _plan() -> tuple[list[Example], dict[str, str]]:
    """The examples to run (deduplicated, producers first) and the reason of each not run."""
    tracked = _tracked()
    parsed = _parsed()
    table = [(ex, _writes(ex, ns)) for ex, ns in parsed]
    skipped: dict[str, str] = {}
    for ex, ns in parsed:
        why = _not_run(ex)
        if why is None:
            for path in _reads(ns):
                if path in PLACEHOLDERS and path not in tracked:
                    why = f"reads {path}: {PLACEHOLDERS[path]}"
        if why is not None:
            skipped[ex.where] = why
    for _ in range(len(parsed)):  # an example whose input comes from one not run is not run
        for ex, ns in parsed:
            if ex.where in skipped:
                continue
            for path in _reads(ns):
                prod = _producer(path, table) if path not in tracked else None
                if prod is not None and prod.where in skipped:
                    skipped[ex.where] = f"reads {path}, written by `{prod.where}` (not run)"
    namespace = {id(ex): ns for ex, ns in parsed}
    order: list[Example] = []
    seen: set[str] = set()

    def add(ex: Example) -> None:  # its producers first, each distinct command once
        key = shlex.join(_shrunk(ex)[0]) + f" > {ex.stdout_to}"
        if ex.where in skipped or key in seen:
            return
        seen.add(key)
        for path in _reads(namespace[id(ex)]):
            prod = _producer(path, table) if path not in tracked else None
            if prod is not None and prod is not ex:
                add(prod)
        order.append(ex)

    for ex, _ in parsed:
        add(ex)
    return order, skipped


def test_not_run_list_is_current() -> None:
    order, skipped = _plan()
    texts = [e.text for e in EXAMPLES]
    for start in NOT_RUN:
        assert any(t.startswith(start) for t in texts), f"NOT_RUN entry matches nothing: {start!r}"
    for start, _, _ in SHRINK:
        assert any(t.startswith(start) for t in texts), f"SHRINK entry matches nothing: {start!r}"
    reasons = [*PLACEHOLDERS.values(), *NOT_RUN.values(), *(why for _, _, why in SHRINK)]
    for named in {m for r in reasons for m in re.findall(r"tests/(?:\w+/)*test_[\w*]+\.py", r)}:
        assert list(ROOT.glob(named)), f"a reason names {named}, which does not exist"
    ran = {e.where for e in order}
    for ex in EXAMPLES:  # each example runs (possibly as an identical one), or says why not
        assert ex.where in skipped or ex.where in ran or any(
            shlex.join(_shrunk(ex)[0]) == shlex.join(_shrunk(o)[0]) for o in order), ex.where


@pytest.fixture
def clone(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A folder laid out as a fresh clone: its tracked top-level folders and files linked in."""
    root = tmp_path / "clone"
    root.mkdir()
    tops = {Path(f).parts[0] for f in _tracked() if f}
    for name in sorted(tops):
        if (ROOT / name).exists():
            (root / name).symlink_to(ROOT / name)
    monkeypatch.chdir(root)
    return root


def _run(argv: list[str], stdout_to: str | None) -> tuple[int, str, str]:
    if argv[0] == "region":  # it forks to write its figures: not from pytest's process
        r = subprocess.run([sys.executable, "-m", "stringstab", *argv], capture_output=True,
                           text=True, timeout=600)
        return r.returncode, r.stdout, r.stderr
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    return rc, out.getvalue(), err.getvalue()


@pytest.mark.slow  # ~70 s of CPU in all, in two halves that xdist runs side by side
@pytest.mark.parametrize("lane", ["region", "the others"])
def test_every_quick_example_runs_from_a_clone(clone: Path, lane: str) -> None:
    order, _ = _plan()
    assert len(order) > 30
    # region's examples read only shipped files and write nothing another example reads
    mine = [ex for ex in order if (ex.argv[0] == "region") == (lane == "region")]
    assert mine
    failures = []
    absent = []
    for ex in mine:
        extra = next((x for start, module, x in EXTRAS
                      if ex.text.startswith(start) and importlib.util.find_spec(module) is None),
                     None)
        if extra is not None:
            absent.append(f"{ex.where} (extra {extra!r})")
            continue
        argv, why = _shrunk(ex)
        rc, out, err = _run(argv, ex.stdout_to)
        if ex.stdout_to:
            Path(ex.stdout_to).write_text(out, encoding="utf-8")
        errors = [s for s in ex.shown if ": error: " in s]
        warnings = [s for s in ex.shown if ": warning: " in s]
        lines = [ln for ln in err.splitlines() if ln.strip()]
        shrunk = f" (shrunk: {why})" if why else ""
        if errors:
            if rc != 2 or lines != errors:
                failures.append(f"{ex.where}{shrunk}: expected exit 2 and {errors}; got {rc}, "
                                f"{lines}")
        elif rc not in (0, 1):
            failures.append(f"{ex.where}{shrunk}: exit {rc}: {err.strip()[-500:]}")
        for w in warnings:
            if w not in lines:
                failures.append(f"{ex.where}: the docs show {w!r}; it printed {lines}")
    assert not failures, "\n".join(failures)
    if absent:
        pytest.skip(f"ran {len(mine) - len(absent)} examples; not run without their optional "
                    f"extra: {absent}")
