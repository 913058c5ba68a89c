"""Issue 21, item 6: random input to every command keeps the README's promise.

Hypothesis builds command lines from each command's own options (read from its parser) with
random values: numeric extremes (±1e308, subnormals, NaN, huge integers), random text and bytes
(as the OS hands them to Python: surrogate-escaped, no NUL) and random paths (missing, a folder,
a file of random bytes).  Each runs in-process (``stringstab.cli.main``) in a fresh folder, with
an alarm that presses Ctrl-C after a few seconds so a valid but long command is interrupted —
exercising that path too.  Asserted: the exit code is 0, 1, 2 or 130; stderr holds no
traceback; a run that failed or was interrupted left no output (no ``--out``, no staging
folder) — a training run interrupted leaves its resumable folder with its log and summary.
"""

import os
import signal
import string
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from stringstab.cli import COMMANDS, build_parser

ALARM_S = 1.0  # Ctrl-C after this long: keeps every example short
#: Examples per run (CI: a few seconds); STRINGSTAB_FUZZ_EXAMPLES=500 for a longer hunt.
EXAMPLES = int(os.environ.get("STRINGSTAB_FUZZ_EXAMPLES", "30"))

EXTREMES = ["1e308", "-1e308", "5e-324", "-5e-324", "2.2250738585072014e-308", "nan", "-nan",
            "inf", "-inf", "0", "-0", "1", "-1", "99999999999999999999999999999999999999",
            "-99999999999999999999", "1e-300", "0.1", "1e6", "1e308,1e308,1e308",
            "nan,1,1", "1,1", "0.3:0.1", "0.1:1e300", "5e-324,5e-324,5e-324", "k_a=1e308",
            "-2,2", "none", "", " ", "--", "-"]


def _options(command: str) -> list[tuple[str, bool]]:
    """(option string, takes a value) of every option of ``command`` (and its sub-commands)."""
    parser = build_parser(command)
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    found: list[tuple[str, bool]] = []

    def walk(p):
        for a in p._actions:
            if a.__class__.__name__ == "_SubParsersAction":
                for q in a.choices.values():
                    walk(q)
            elif a.option_strings and a.option_strings[0] not in ("-h", "--help"):
                found.append((a.option_strings[-1], a.nargs != 0))

    walk(sub.choices[command])
    return sorted(set(found))


OPTIONS = {c: _options(c) for c in COMMANDS}
SUBCOMMANDS = {"hcfs": ["verify", "train"]}


def _text():
    raw = st.binary(max_size=12).map(lambda b: b.replace(b"\0", b"").decode(
        "utf-8", errors="surrogateescape"))
    return st.one_of(st.sampled_from(EXTREMES), st.text(string.printable, max_size=10).filter(
        lambda s: "\0" not in s), raw)


@st.composite
def command_lines(draw):
    command = draw(st.sampled_from(COMMANDS))
    argv = [command]
    if command in SUBCOMMANDS:
        argv.append(draw(st.sampled_from(SUBCOMMANDS[command])))
    for _ in range(draw(st.integers(0, 4))):  # positionals (triples, runs, files)
        argv.append(draw(st.one_of(_text(), st.sampled_from(["@file", "@dir", "@missing"]))))
    for _ in range(draw(st.integers(0, 4))):
        opt, takes = draw(st.sampled_from(OPTIONS[command]))
        if opt in ("--out", "-o"):
            continue  # --out is always given, below
        argv.append(opt)
        if takes:
            argv.append(draw(st.one_of(_text(), st.sampled_from(["@file", "@dir", "@missing"]))))
    if "--out" in dict(OPTIONS[command]) or command == "hcfs":
        argv += ["--out", draw(st.sampled_from(["@out", "@out/x.json", "@out/x.csv"]))]
    return argv


#: Small valid command lines: a random option with an extreme value is appended to one, so the
#: checks behind the parser (and the work itself, until the alarm) are reached too.
BASES = [
    ["certify", "1.2,0.5,0.6"],
    ["certify", "--file", "@file"],
    ["tune", "0.9,-0.5,1.1"],
    ["region", "--fix", "k_a=0.5", "--n", "5", "--no-progress", "--out", "@out"],
    ["simulate", "--duration", "5", "--followers", "2", "--no-figures", "--out", "@out"],
    ["hcfs", "verify", "-J", "2.5", "--followers", "2", "--policy", "stand-in", "--duration", "5",
     "--no-figures", "--no-progress", "--out", "@out"],
    ["demo", "--only", "certify", "--out", "@out"],
    ["train", "--algo", "ddpg", "--steps", "64", "--num-envs", "4", "--no-progress", "--out", "@out"],
]


@st.composite
def perturbed_lines(draw):
    base = list(draw(st.sampled_from(BASES)))
    command = base[0]
    for _ in range(draw(st.integers(1, 2))):
        opt, takes = draw(st.sampled_from(OPTIONS[command]))
        if opt in ("--out", "-o"):
            continue
        base[-2:-2] = [opt, *([draw(st.one_of(_text(), st.sampled_from(["@file", "@dir"])))]
                              if takes else [])] if "--out" in base else []
        if "--out" not in base:
            base += [opt, *([draw(_text())] if takes else [])]
    return base


class _Alarm:
    """SIGALRM after ``seconds`` → SIGINT to this process (what Ctrl-C sends)."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds

    def __enter__(self):
        self.old = signal.signal(signal.SIGALRM, lambda *_: os.kill(os.getpid(), signal.SIGINT))
        # again every `seconds` (a user pressing Ctrl-C again): a swallowed first one cannot
        # hang the test, and the time it took says that it was swallowed
        signal.setitimer(signal.ITIMER_REAL, self.seconds, self.seconds)
        return self

    def __exit__(self, *exc):
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, self.old)
        signal.signal(signal.SIGINT, signal.default_int_handler)


def _staging_left(root: Path) -> list[Path]:
    return [p for p in root.rglob(".stringstab-staging-*")]


@pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="needs POSIX interval timers")
@settings(max_examples=EXAMPLES, deadline=None, phases=[Phase.explicit, Phase.reuse, Phase.generate],
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(argv=st.one_of(command_lines(), perturbed_lines()), payload=st.binary(max_size=64))
def test_random_command_lines_fail_as_one_sentence(argv, payload, tmp_path_factory, capsys,
                                                    monkeypatch):
    from stringstab.cli import main

    root = tmp_path_factory.mktemp("fuzz")
    monkeypatch.chdir(root)  # defaults such as demo's ./demo-out land here
    (root / "in").mkdir()
    (root / "in" / "f.csv").write_bytes(payload)
    out = root / "o"  # an existing empty folder: single-file outputs go inside it
    out.mkdir()
    subst = {"@file": str(root / "in" / "f.csv"), "@dir": str(root / "in"),
             "@missing": str(root / "missing" / "x"), "@out": str(out),
             "@out/x.json": str(out / "x.json"), "@out/x.csv": str(out / "x.csv")}
    args = [subst.get(a, a) for a in argv]
    code = None
    t0 = time.monotonic()
    try:
        with _Alarm(ALARM_S):
            try:
                code = main(args)
            except SystemExit as e:  # argparse: --help/--version (0) or a usage error (2)
                code = e.code if isinstance(e.code, int) else 2
    except KeyboardInterrupt:  # the alarm fired outside main (before it, or after its return)
        code = 130 if code is None else code
    took = time.monotonic() - t0
    captured = capsys.readouterr()
    if os.environ.get("STRINGSTAB_FUZZ_LOG"):  # what was tried, for a human to look at
        with open(os.environ["STRINGSTAB_FUZZ_LOG"], "a", encoding="utf-8",
                  errors="backslashreplace") as f:
            f.write(f"{code}\t{args!r}\t{captured.err.strip().splitlines()[-1:]!r}\n")
    assert code in (0, 1, 2, 130), (args, code, captured.err[-2000:])
    assert took < 15 * ALARM_S, (args, f"Ctrl-C was not obeyed for {took:.0f} s")
    assert "Traceback" not in captured.err, (args, captured.err[-3000:])
    assert not _staging_left(root), args
    if code in (2, 130):
        left = sorted(out.iterdir()) if out.is_dir() else []
        if argv[0] == "train" and code == 130 and left:  # a resumable run folder
            assert (out / "summary.json").is_file() and (out / "train_log.csv").is_file(), args
        else:
            assert not left, (args, code, left)
