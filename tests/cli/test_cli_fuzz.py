"""Issues 21 (item 6) and 29 (item 8): random and hostile input to every command keeps the README's promise.

Hypothesis builds command lines from each command's own options (read from its parser) with
random values: numeric extremes (±1e308, subnormals, NaN, huge integers), random text and bytes
(as the OS hands them to Python: surrogate-escaped, no NUL) and random paths (missing, a folder,
a file of random bytes).  Each runs in-process (``stringstab.cli.main``) in a fresh folder, with
an alarm that presses Ctrl-C after a few seconds so a valid but long command is interrupted —
exercising that path too.  Asserted: the exit code is 0, 1, 2 or 130; stderr holds no
traceback; a run that failed or was interrupted left no output (no ``--out``, no staging
folder) — a training run interrupted leaves its resumable folder with its log and summary.

Beside the random search, deterministic cases (issue 29): a binary file, a Latin-1 file and a
gzip-compressed Latin-1 file for every file argument of every command (and for every file a folder argument makes it read), and
NaN, inf, a negative and a huge value for every numeric flag — each one line on stderr, exit 2,
no traceback, nothing on stdout, no output.
"""

import gzip
import json
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
    ["simulate", "--duration", "15", "--followers", "2", "--no-figures", "--out", "@out"],
    ["hcfs", "verify", "-J", "2.5", "--followers", "2", "--policy", "stand-in", "--duration", "15",
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


def _warm_imports() -> None:
    """Import the heavy libraries once, before any alarm can fire.

    Every example runs in this one process: a Ctrl-C landing inside a first ``import torch``
    (several seconds under load) leaves half-imported submodules behind, which breaks every later
    import of torch in the process — an artefact of reusing the process, not of the command
    (run as ``stringstab``, an interrupted import ends the process with exit 130).
    """
    import importlib

    for name in ("torch", "torch._dynamo", "torch.optim", "safetensors.numpy", "matplotlib.pyplot",
                 "gymnasium", "sympy", "scipy.signal", "casadi", "distributed", "pyarrow.parquet",
                 "control"):
        try:
            importlib.import_module(name)
        except ImportError:
            pass


def _staging_left(root: Path) -> list[Path]:
    return [p for p in root.rglob(".stringstab-staging-*")]


@pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="needs POSIX interval timers")
@settings(max_examples=EXAMPLES, deadline=None, phases=[Phase.explicit, Phase.reuse, Phase.generate],
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(argv=st.one_of(command_lines(), perturbed_lines()), payload=st.binary(max_size=64))
def test_random_command_lines_fail_as_one_sentence(argv, payload, tmp_path_factory, capsys,
                                                    monkeypatch):
    from stringstab.cli import main

    _warm_imports()  # (cached by Python after the first example)
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


# --------------------------------------------------------------------------- issue 29, item 8
# Deterministic cases: a binary file and a non-UTF-8 text file for every file argument of every
# command, and NaN, inf, a negative and a huge value for every numeric flag.  Each must be one
# line on stderr ("stringstab CMD: error: ..."), exit 2, no traceback, nothing on stdout and no
# output written.

BINARY = bytes(range(256)) * 4  # NUL and bytes that are no UTF-8
LATIN1 = "t,v\n0,10\n1,caf\xe9\n".encode("latin-1")  # text, but Latin-1
#: gzip is recognised by content by the one reader (io.text_input): Latin-1 inside it is refused too
PAYLOADS = {"binary": BINARY, "latin-1": LATIN1, "gzip latin-1": gzip.compress(LATIN1, mtime=0)}
HUGE_INT = "99999999999999999999"


def _refused(argv, capsys, root: Path, out: Path | None = None) -> str:
    """Run ``argv``; assert the refusal contract; return the error line."""
    from stringstab.cli import main

    try:
        code = main(argv)
    except SystemExit as e:  # pragma: no cover - argparse exits through _Parser.exit
        code = e.code
    stdout, err = capsys.readouterr()
    lines = err.strip().splitlines()
    head = f"stringstab {argv[0]}"
    assert code == 2, (argv, code, err[-2000:])
    assert len(lines) == 1 and lines[0].startswith(head) and ": error: " in lines[0], (argv, err)
    assert "Traceback" not in err and stdout == "", (argv, stdout[-500:])
    assert out is None or not out.exists() or not any(out.iterdir()), (argv, sorted(out.iterdir()))
    assert not _staging_left(root), argv
    return lines[0]


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """Valid inputs the cases need: a trained run, a recorded platoon, a sweep spec, HCFS policy."""
    import shutil

    import numpy as np

    from stringstab.cli import main
    from stringstab.hcfs.ddpg import bundled_policy_dir
    from stringstab.traffic import LinearController, from_speed, simulate

    root = tmp_path_factory.mktemp("inputs")
    run = root / "run"
    assert main(["train", "--algo", "ddpg", "--steps", "64", "--num-envs", "2", "--seed", "0",
                 "--no-progress", "--out", str(run)]) == 0
    t = np.arange(0.0, 60.05, 0.1)
    lead = from_speed(t, 15 + np.sin(0.5 * t), dt=0.1)
    r = simulate(lead, LinearController([0.2], [0.7], [0.0], headway=1.5, standstill=4.0), 1,
                 tau=0.3, delta=0.0)
    log = root / "log.csv"
    log.write_text("t,v0,v1,gap1\n" + "".join(
        f"{a:.1f},{b:.6f},{c:.6f},{d:.6f}\n" for a, b, c, d in zip(t, r.speed[0], r.speed[1], r.gap[0])))
    leader = root / "lead.csv"
    leader.write_text("t,v\n" + "".join(f"{a:.1f},{b:.6f}\n" for a, b in zip(t, lead.speed)))
    spec = root / "spec.toml"
    spec.write_text('[sweep]\nname = "tiny"\nkind = "certify"\n[base]\nn = 3\n')
    hcfs = root / "hcfs"
    shutil.copytree(bundled_policy_dir(), hcfs)
    # platoon: a CSV list of two followers, and an identify.json naming a log of two followers
    string = root / "string.csv"
    string.write_text("name,k_x,k_v,k_a,tau,delta,headway\nacc,0.2,0.7,0,0.3,0,1.5\n"
                      "cav,0.5,1.0,0.6,0.2,0.2,2.0\n")
    r2 = simulate(lead, LinearController([0.2] * 2, [0.7] * 2, [0.0] * 2, headway=1.5, standstill=4.0),
                  2, tau=0.3, delta=0.0)
    log2 = root / "log2.csv"
    log2.write_text("t,v0,v1,v2,gap1,gap2\n" + "".join(
        f"{t[k]:.1f},{r2.speed[0][k]:.6f},{r2.speed[1][k]:.6f},{r2.speed[2][k]:.6f},"
        f"{r2.gap[0][k]:.6f},{r2.gap[1][k]:.6f}\n" for k in range(t.size)))
    ident = root / "identify.json"
    ident.write_text(json.dumps({"command": "identify", "skipped": [], "sources": [str(log2)],
                                 "vehicles": [{"platoon": 0, "position": p, "name": f"car{p}",
                                               "predecessor": f"car{p - 1}", "k_x": 0.2, "k_v": 0.7,
                                               "k_a": 0.0, "tau": 0.3, "delta": 0.0, "headway": 1.5,
                                               "standstill": 4.0} for p in (1, 2)]}))
    return {"run": run, "log": log, "leader": leader, "spec": spec, "hcfs": hcfs, "string": string,
            "log2": log2, "identify": ident}


def _sumo() -> bool:
    import importlib.util

    return importlib.util.find_spec("libsumo") is not None


#: Every file argument of every command: {F} is the bad file (its extension given), {O} an output
#: path, {RUN} a trained run.
FILE_ARGUMENTS = [
    ["certify", "--file", "{F}.csv"],
    ["certify", "--file", "{F}.json"],
    ["certify", "--file", "{F}.npz"],
    ["certify", "--file", "{F}.parquet"],
    ["certify", "--from", "{F}.json"],
    ["region", "--fix", "k_a=0.5", "--n", "5", "--no-progress", "--overlay", "{F}.csv", "--out", "{O}"],
    ["tune", "--file", "{F}.csv"],
    ["tune", "--file", "{F}.json", "--report", "{O}"],
    ["simulate", "--leader", "{F}.csv", "--no-figures", "--out", "{O}"],
    ["simulate", "--leader", "{F}", "--no-figures", "--out", "{O}"],  # no extension: a path
    ["simulate", "--gains-file", "{F}.csv", "--no-figures", "--out", "{O}"],
    ["simulate", "--from", "{F}.json", "--no-figures", "--out", "{O}"],
    ["train", "--algo", "ddpg", "--steps", "8", "--leaders", "{F}.csv", "--no-progress", "--out", "{O}"],
    ["evaluate", "{RUN}", "--leaders", "{F}.csv", "--platoon", "none", "--no-progress", "--out", "{O}"],
    ["compare", "{RUN}", "--baselines", "none", "--leaders", "{F}.csv", "--no-progress", "--out", "{O}"],
    ["hcfs", "verify", "-J", "2.5", "--policy", "stand-in", "--leader", "{F}.csv", "--no-figures",
     "--no-progress", "--out", "{O}"],
    ["hcfs", "train", "--steps", "8", "--leader", "{F}.csv", "--no-progress", "--out", "{O}"],
    ["identify", "{F}.csv", "--no-progress", "--out", "{O}"],
    ["identify", "{F}", "--no-progress", "--out", "{O}"],
    ["sweep", "{F}.toml", "--out", "{O}"],
    ["sumo", "check", "--leader", "{F}.csv"],
    ["sumo", "check", "--gains-file", "{F}.csv"],
    ["sumo", "run", "--leader", "{F}.csv", "--out", "{O}"],
    ["sumo", "run", "--gains-file", "{F}.csv", "--out", "{O}"],
    ["sumo", "run", "--sumocfg", "{F}.sumocfg", "--controlled", "a", "--out", "{O}"],
    ["sumo", "cacc", "--vtype", "{F}.rou.xml:cacc"],
    ["platoon", "certify", "{F}.csv"],
    ["platoon", "certify", "{F}.json"],
    ["platoon", "certify", "{F}"],
    ["platoon", "design", "--from", "{F}.csv", "--cav-at", "1"],
    ["platoon", "design", "--from", "{F}.json", "--cav-at", "1"],
    ["platoon", "simulate", "--from", "{F}.json", "--cav-at", "1", "--cav-gains", "0.5,1,0.6",
     "--no-figures", "--out", "{O}"],
    ["radio", "--leader", "{F}.csv", "--followers", "2", "--seeds", "2", "--no-figures",
     "--no-progress", "--out", "{O}"],
]
#: Files read inside a folder argument: (argv with {D}, the folder's source, the file replaced).
FOLDER_FILES = [
    (["evaluate", "{D}", "--platoon", "none", "--no-progress", "--out", "{O}"], "run", "policy.json"),
    (["compare", "{D}", "--baselines", "none", "--no-progress", "--out", "{O}"], "run", "policy.json"),
    (["train", "--algo", "ddpg", "--steps", "128", "--num-envs", "2", "--resume", "--no-progress",
      "--out", "{D}"], "run", "run.json"),
    (["train", "--algo", "ddpg", "--steps", "128", "--num-envs", "2", "--resume", "--no-progress",
      "--out", "{D}"], "run", "checkpoint/latest.json"),
    (["hcfs", "verify", "-J", "2.5", "--policy", "{D}", "--no-figures", "--no-progress",
      "--out", "{O}"], "hcfs", "hcfs_policy.json"),
    (["hcfs", "verify", "-J", "2.5", "--policy", "{D}", "--no-figures", "--no-progress",
      "--out", "{O}"], "hcfs", "policy.json"),
    (["sumo", "run", "--policy", "{D}", "--out", "{O}"], "run", "policy.json"),
]


def _subst(argv, **kw):
    return [a.format(**kw) if "{" in a else a for a in argv]


@pytest.mark.parametrize("payload", sorted(PAYLOADS))
@pytest.mark.parametrize("argv", FILE_ARGUMENTS, ids=lambda a: " ".join(a[:4]))
def test_every_file_argument_refuses_undecodable_bytes(argv, payload, inputs, tmp_path, capsys):
    if argv[0] == "sumo" and not _sumo():
        pytest.skip("needs the optional extra 'sumo'")
    f, out = tmp_path / "f", tmp_path / "out"
    args = _subst(argv, F=f, O=out, RUN=inputs["run"])
    bad = next(Path(a.split(":")[0]) for a in args if a.startswith(str(f)))
    bad.write_bytes(PAYLOADS[payload])
    line = _refused(args, capsys, tmp_path, out)
    assert bad.name in line and "expected" in line, line


@pytest.mark.parametrize("payload", sorted(PAYLOADS))
@pytest.mark.parametrize("argv, source, name", FOLDER_FILES, ids=lambda a: str(a)[:40])
def test_every_file_read_in_a_folder_argument_refuses_undecodable_bytes(argv, source, name, payload,
                                                                      inputs, tmp_path, capsys):
    import shutil

    if argv[0] == "sumo" and not _sumo():
        pytest.skip("needs the optional extra 'sumo'")
    d, out = tmp_path / "d", tmp_path / "out"
    shutil.copytree(inputs[source], d)
    (d / name).write_bytes(PAYLOADS[payload])
    line = _refused(_subst(argv, D=d, O=out), capsys, tmp_path, out)
    assert Path(name).name in line and "expected" in line, line


#: The recorded log an identify.json names (read by platoon simulate's replay).
LOG_NAMED = [["platoon", "simulate", "--from", "{J}", "--cav-at", "1", "--cav-gains", "0.5,1,0.6",
              "--no-figures", "--out", "{O}"]]


@pytest.mark.parametrize("payload", sorted(PAYLOADS))
@pytest.mark.parametrize("argv", LOG_NAMED, ids=lambda a: " ".join(a[:2]))
def test_every_log_named_in_an_identify_json_refuses_undecodable_bytes(argv, payload, inputs,
                                                                        tmp_path, capsys):
    bad, out, j = tmp_path / "log.csv", tmp_path / "out", tmp_path / "identify.json"
    bad.write_bytes(PAYLOADS[payload])
    doc = json.loads(inputs["identify"].read_text())
    doc["sources"] = [str(bad)]
    j.write_text(json.dumps(doc))
    line = _refused(_subst(argv, J=j, O=out), capsys, tmp_path, out)
    assert bad.name in line and "expected" in line, line


#: A valid, quick command line of each command (sub-command); {O} an output path, {RUN} etc.
NUMERIC_BASES = {
    "derive": ["derive"],
    "certify": ["certify", "1.2,0.5,0.6"],
    "region": ["region", "--fix", "k_a=0.5", "--n", "5", "--no-progress", "--out", "{O}"],
    "tune": ["tune", "0.9,-0.5,1.1"],
    "simulate": ["simulate", "--leader", "sinusoid:omega=0.5", "--duration", "20", "--followers", "2",
                 "--no-figures", "--out", "{O}"],
    "train": ["train", "--algo", "ddpg", "--steps", "64", "--num-envs", "2", "--no-progress",
              "--out", "{O}"],
    "evaluate": ["evaluate", "{RUN}", "--platoon", "none", "--leaders", "{LEADER}", "--no-progress",
                 "--out", "{O}"],
    "compare": ["compare", "{RUN}", "--baselines", "none", "--leaders", "{LEADER}", "--no-progress",
                "--out", "{O}"],
    "hcfs verify": ["hcfs", "verify", "-J", "2.5", "--followers", "2", "--policy", "stand-in",
                    "--duration", "20", "--no-figures", "--no-progress", "--out", "{O}"],
    "hcfs train": ["hcfs", "train", "--steps", "64", "--no-progress", "--out", "{O}"],
    "identify": ["identify", "{LOG}", "--bootstrap", "0", "--starts", "1", "--no-figures",
                 "--no-progress", "--out", "{O}"],
    "sweep": ["sweep", "{SPEC}", "--workers", "1", "--no-progress", "--out", "{O}"],
    "demo": ["demo", "--only", "certify", "--out", "{O}"],
    "sumo run": ["sumo", "run", "--leader", "sinusoid:omega=0.5", "--duration", "20", "--followers", "2",
                 "--no-figures", "--out", "{O}"],
    "radio": ["radio", "--gains", "1.2,0.5,0.6", "--leader", "sinusoid:omega=0.5", "--duration", "20",
              "--hold", "0", "--followers", "2", "--seeds", "2", "--loss", "0,0.1", "--burst", "1",
              "--no-figures", "--no-progress", "--out", "{O}"],
    "platoon certify": ["platoon", "certify", "{IDENT}", "--no-empirical"],
    "platoon design": ["platoon", "design", "--from", "{IDENT}", "--cav-at", "2"],
    "platoon simulate": ["platoon", "simulate", "--from", "{IDENT}", "--cav-at", "2", "--cav-gains",
                         "0.5,1,0.6", "--no-figures", "--out", "{O}"],
}
FLOATS = ["nan", "inf", "-1", "1e300"]
INTS = ["nan", "inf", "-1", HUGE_INT]
GAINS = ["nan,0.5,0.6", "inf,0.5,0.6", "1e300,0.5,0.6"]  # a negative gain is valid
A_MIN = ["nan", "-inf", "1", "-1e300"]  # a braking limit is negative
SAMPLE = [*FLOATS, "1e-300"]  # a sample time or step also has a floor (1e-300 divided by zero)
#: The loop's flags (cli/_loop.py: θ_r, the radio, the sensors) of simulate, sumo run, train,
#: evaluate and compare.
LOOP = {"--reaction-delay": FLOATS, "--message-period": FLOATS, "--message-phase": INTS,
        "--loss": FLOATS, "--burst": FLOATS, "--stale-after": FLOATS,
        "--fallback-gains": ["nan,0.5", "inf,0.5", "1e300,0.5"], "--noise-gap": FLOATS,
        "--noise-gap-rate": FLOATS, "--noise-speed": FLOATS, "--noise-correlation": FLOATS,
        "--noise-filter": FLOATS, "--radio-seed": INTS}
#: What a flag needs beside it (its value is checked only then); (command, flag) before flag.
NEEDS = {"--burst": ["--loss", "0.1"], "--message-phase": ["--message-period", "0.2"],
         "--fallback-gains": ["--stale-after", "0.5"], "--radio-seed": ["--loss", "0.1"],
         ("certify", "--message-period"): ["--sample-time", "0.01"],
         ("certify", "--max-message-period"): ["--sample-time", "0.01"],
         ("certify", "--message-phase"): ["--sample-time", "0.01", "--message-period", "0.1"],
         ("certify", "--fallback-gains"): ["--sample-time", "0.01", "--message-period", "0.1"],
         ("region", "--message-period"): ["--sample-time", "0.01"],
         ("region", "--message-phase"): ["--sample-time", "0.01", "--message-period", "0.1"],
         ("platoon certify", "--leader-tau"): ["--sample-time", "0.1"]}
#: The multi-rate loop's flags of certify and region (cli/_message.py, issue 26).
MESSAGE = {"--message-period": FLOATS, "--message-phase": INTS}
#: platoon: the string's own flags, and the CAV's (cli/platoon.py, issue 27).
STRING = {"--platoon": INTS, "--positions": [*INTS, "1:nan", f"1:{HUGE_INT}"]}
CAV = {"--cav-at": INTS, "--cav-tau": FLOATS, "--cav-delta": FLOATS, "--cav-headway": FLOATS,
       "--cav-reaction-delay": FLOATS, "--gain-bounds": ["nan:2", "-inf:2", "-1e300:2", "-2:1e300"],
       "--min-kx": FLOATS, "--max-cavs": INTS}
#: Every numeric flag of every command (sumo's own are listed in SUMO_NUMERIC) and its bad values.
NUMERIC = {
    "derive": {"--delay-order": INTS, "--sample-time": SAMPLE, "--reaction-delay": FLOATS,
               "--substitute": [f"{k}={v}" for k in ("tau", "reaction_delay") for v in FLOATS]},
    "certify": {"K_X,K_V,K_A": GAINS, "--tau": FLOATS, "--delta": FLOATS, "--headway": FLOATS,
                "--sample-time": SAMPLE, "--pade-order": INTS,
                # θ_r as an interval: the box certificate (issue 25, item 4)
                "--reaction-delay": [*FLOATS, "0.3:0.1", "-0.1:0.2", "nan:0.2", "0.1:1e300"]},
    "region": {"--fix": ["k_a=nan", "k_a=inf", "k_a=1e300"], "--range": ["nan,2", "-inf,2", "-1e300,2"],
               "--n": INTS, "--tau": FLOATS, "--delta": FLOATS, "--headway": FLOATS,
               "--sample-time": SAMPLE, "--dpi": INTS, "--workers": INTS, "--reaction-delay": FLOATS},
    "tune": {"K_X,K_V,K_A": GAINS, "--tau": FLOATS, "--delta": FLOATS, "--headway": FLOATS,
             "--sample-time": SAMPLE, "--bounds": ["nan,2", "-inf,2", "-1e300,2"],
             "--weights": [f"{v},1,1" for v in FLOATS], "--r0": FLOATS, "--grid": INTS,
             "--max-iter": INTS, "--hurwitz-margin": FLOATS, "--eps": FLOATS,
             "--reaction-delay": FLOATS},
    "simulate": {"--followers": INTS, "--gains": GAINS, "--vehicle": INTS, "--tau": FLOATS,
                 "--delta": FLOATS, "--headway": FLOATS, "--standstill": FLOATS,
                 "--length": FLOATS, "--dt": SAMPLE, "--duration": FLOATS, "--hold": FLOATS,
                 "--ttc-star": FLOATS, "--v-max": FLOATS, "--a-min": A_MIN, "--a-max": FLOATS,
                 **LOOP},
    "train": {"--steps": INTS, "--seed": INTS, "--num-envs": INTS, "--stop-episodes": INTS,
              **LOOP},
    "evaluate": {"--platoon": [f"{v},10" for v in INTS], "--v-max": FLOATS, "--a-min": A_MIN,
                 "--a-max": FLOATS, **LOOP},
    "compare": {"--v-max": FLOATS, "--a-min": A_MIN, "--a-max": FLOATS, **LOOP},
    "hcfs verify": {"--jerk-limit": ["nan", "inf", "-1", "1e9"], "--followers": INTS,
                    "--duration": FLOATS, "--beta": FLOATS, "--v-max": FLOATS, "--a-min": A_MIN,
                    "--a-max": FLOATS},
    "hcfs train": {"--steps": INTS, "--seed": INTS, "--platoons": INTS, "--followers": INTS,
                   "--episode-seconds": FLOATS},
    "identify": {"--sample-time": SAMPLE, "--bootstrap": INTS, "--block": FLOATS, "--starts": INTS,
                 "--seed": INTS, "--min-segment": FLOATS},
    "sweep": {"--workers": INTS, "--retries": INTS},
    "demo": {"--v-max": FLOATS, "--a-min": A_MIN, "--a-max": FLOATS},
    "radio": {"--gains": GAINS, "--followers": INTS, "--tau": FLOATS, "--delta": FLOATS,
              "--headway": FLOATS, "--standstill": FLOATS, "--length": FLOATS, "--dt": SAMPLE,
              "--duration": FLOATS, "--hold": FLOATS, "--loss": [*FLOATS, "0,nan", "0,1e300"],
              "--burst": [*FLOATS, "1,nan", "1,1e300"], "--seeds": INTS, "--v-max": FLOATS,
              "--a-min": A_MIN, "--a-max": FLOATS,
              **{k: v for k, v in LOOP.items() if k not in ("--loss", "--burst")}},
    "sumo run": {"--followers": INTS, "--gains": GAINS, "--tau": FLOATS, "--delta": FLOATS,
                 "--headway": FLOATS, "--standstill": FLOATS, "--length": FLOATS, "--dt": SAMPLE,
                 "--duration": FLOATS, "--hold": FLOATS, "--steps": INTS, "--v-max": FLOATS,
                 "--a-min": A_MIN, "--a-max": FLOATS, **LOOP},
    "platoon certify": {**STRING, "--sample-time": SAMPLE, "--leader-tau": FLOATS},
    "platoon design": {**STRING, **CAV},
    "platoon simulate": {**STRING, **CAV, "--cav-gains": GAINS},
}
NUMERIC["certify"].update(MESSAGE, **{"--fallback-gains": ["nan,0.5", "inf,0.5", "1e300,0.5"],
                                      "--max-message-period": FLOATS})
NUMERIC["region"].update(MESSAGE)
#: sumo check's and sumo cacc's numeric flags: not fuzzed yet (sumo run's are, in NUMERIC).
SUMO_NUMERIC = {"sumo check": {"--followers", "--gains", "--tau", "--delta", "--headway", "--standstill",
                               "--length", "--dt", "--duration", "--hold", "--tolerance",
                               "--v-max", "--a-min", "--a-max"},
                "sumo cacc": {"--followers", "--duration", "--dt"}}
#: The other value-taking options: file arguments (FILE_ARGUMENTS), names and text.
NOT_NUMERIC = {"--out", "--file", "--from", "--overlay", "--report", "--leader", "--leaders",
               "--gains-file", "--policy", "--json", "--sumocfg", "--vtype", "--scheduler",
               "--algo", "--baselines", "--reference", "--controlled", "--x", "--y", "--method",
               "--prefix", "--format", "--only", "RUN", "LOG", "SPEC", "FILE"}


def _value_options() -> dict[str, set[str]]:
    """Every value-taking option (and positional) without fixed choices, per command."""
    out: dict[str, set[str]] = {}

    def walk(p, path):
        for a in p._actions:
            if a.__class__.__name__ == "_SubParsersAction":
                for name, q in a.choices.items():
                    walk(q, f"{path} {name}")
            elif a.nargs == 0 or a.choices or "--help" in a.option_strings:
                continue
            else:
                name = next((o for o in a.option_strings if o.startswith("--")), a.metavar)
                out.setdefault(path, set()).add(name)

    for c in COMMANDS:
        parser = build_parser(c)
        sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
        walk(sub.choices[c], c)
    return out


def test_every_numeric_flag_has_its_out_of_range_cases():
    """A new numeric flag without cases here fails: the fuzz covers every one."""
    for command, options in _value_options().items():
        covered = set(NUMERIC.get(command, {})) | SUMO_NUMERIC.get(command, set()) | NOT_NUMERIC
        assert options - covered == set(), (command, options - covered)


NUMERIC_CASES = [(c, flag, v) for c, flags in NUMERIC.items() for flag, vs in flags.items() for v in vs]


@pytest.mark.parametrize("command, flag, value", NUMERIC_CASES, ids=lambda x: str(x))
def test_every_numeric_flag_refuses_nan_inf_negative_and_huge(command, flag, value, inputs,
                                                               tmp_path, capsys):
    if command.startswith("sumo") and not _sumo():
        pytest.skip("needs the optional extra 'sumo'")
    out = tmp_path / "out"
    argv = _subst(NUMERIC_BASES[command], O=out, RUN=inputs["run"], LEADER=inputs["leader"],
                  LOG=inputs["log"], SPEC=inputs["spec"], IDENT=inputs["identify"])
    if flag == "K_X,K_V,K_A":
        argv[len(command.split())] = value
    elif flag in argv:
        argv[argv.index(flag) + 1] = value
    else:
        argv += [flag, value, *NEEDS.get((command, flag), NEEDS.get(flag, []))]
    line = _refused(argv, capsys, tmp_path, out)
    assert "expect" in line or "must" in line or "far outside" in line, line  # what was expected
