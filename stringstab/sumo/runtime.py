"""Starting and stopping Eclipse SUMO: libsumo (in process, the default) or TraCI (a subprocess).

Every session runs with the ballistic position update (``--step-method.ballistic``) and the
controller's step (``--step-length``); a configuration that asks for another step or for the
Euler update is refused before SUMO starts, and the running simulation is asked for both again
after it has started (:func:`check_running`).

libsumo runs one simulation per process: :class:`SumoSession` refuses to start a second one
while the first is open.  TraCI starts the ``sumo`` binary of the ``eclipse-sumo`` wheel as a
subprocess, connects to it on 127.0.0.1 and closes it (the subprocess is killed if it does not
exit) in a ``finally``, also on errors and Ctrl-C.  SUMO 1.28's TraCI server binds its listening
socket to every address (``INADDR_ANY`` in its ``tcpip::Socket::accept``; SUMO has no option to
choose the address) from its start until the first client connects, then closes it
(``--num-clients 1``); the session checks on Linux that the one connection SUMO accepted is its
own (:func:`_check_peer`).  libsumo opens no socket at all.

The extra (``pip install 'stringstab[sumo]'``, the 1.28 series) is imported only here and only
when a session starts; without it the error is one line naming the extra.
"""

from __future__ import annotations

import contextlib
import io
import os
import socket
import subprocess
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Literal

from ..errors import StringStabError, show

__all__ = ["API", "EXTRA", "SUMO_SERIES", "SumoSession", "binary", "check_config", "import_api",
           "read_xml"]

API = Literal["libsumo", "traci"]
#: The optional extra that installs SUMO.
EXTRA = "pip install 'stringstab[sumo]'"
#: The SUMO release series the co-simulation is written and tested against.
SUMO_SERIES = "1.28"

_ACTIVE_LIBSUMO: list[object] = []  # the open libsumo session, if any (one per process)


def import_api(api: str) -> Any:
    """The SUMO Python module for ``api`` ('libsumo' or 'traci'), imported on first use.

    libsumo prints a warning at import when the installed pyarrow's version differs from the
    libarrow it was built against.  libsumo's wheel carries its own (renamed) libarrow, used
    only for SUMO's Parquet outputs, which the toolkit never asks for; the warning is printed
    to Python's stdout and is kept out of the user's output here.

    Parameters
    ----------
    api : {"libsumo", "traci"}
        Which SUMO Python interface to import (sumolib is imported too).

    Returns
    -------
    module
        The ``libsumo`` or ``traci`` module.

    Raises
    ------
    StringStabError
        If ``api`` is neither, or the extra is not installed (one line naming it).
    """
    if api not in ("libsumo", "traci"):
        raise StringStabError(f"--api must be 'libsumo' or 'traci'; got {show(api)}")
    try:
        if api == "libsumo":
            with contextlib.redirect_stdout(io.StringIO()):
                import libsumo as mod
        else:
            import traci as mod
        import sumolib  # noqa: F401
    except ImportError as e:
        raise StringStabError(
            f"running SUMO needs the optional extra 'sumo' (eclipse-sumo, libsumo, traci, sumolib "
            f"{SUMO_SERIES}.x): {EXTRA}; {api} could not be imported ({e})"
        ) from e
    return mod


def binary(name: str) -> str:
    """Path of a SUMO program (``sumo``, ``netconvert``) from the ``eclipse-sumo`` wheel.

    Parameters
    ----------
    name : str
        The program's name.

    Returns
    -------
    str
        Its path (as found by ``sumolib.checkBinary``).

    Raises
    ------
    StringStabError
        If the SUMO extra is not installed or the program is not there.
    """
    import_api("traci")
    import sumolib

    path = sumolib.checkBinary(name)
    if not Path(path).is_file():
        raise StringStabError(
            f"the SUMO program {name!r} was not found (looked for {path}); expected the "
            f"eclipse-sumo wheel of the extra: {EXTRA}")
    return str(path)


def _truthy(text: str | None) -> bool:
    return str(text).strip().lower() in ("true", "1", "yes", "on", "x")


def read_xml(path: str | os.PathLike[str], option: str, expected: str, kind: str) -> ET.Element:
    """The root element of a SUMO XML file, or a one-line error naming the option.

    Parameters
    ----------
    path : path-like
        The file.
    option : str
        The command-line option that gave it (e.g. ``"--sumocfg"``), for the message.
    expected : str
        What was expected when the file is missing (e.g. ``"a SUMO configuration file"``).
    kind : str
        What was expected when it does not parse (e.g. ``"a SUMO configuration (XML)"``).

    Returns
    -------
    xml.etree.ElementTree.Element
        The document's root.

    Raises
    ------
    StringStabError
        The file is missing or is not well-formed XML.
    """
    p = Path(path)
    if not p.is_file():
        raise StringStabError(f"{option}: expected {expected}; {str(p)!r} does not exist")
    try:
        return ET.parse(p).getroot()
    except (ET.ParseError, OSError) as e:
        raise StringStabError(f"{option} {p}: expected {kind}; {e}") from e


def check_config(sumocfg: str | os.PathLike[str], dt: float) -> None:
    """Refuse a ``.sumocfg`` whose step length is not ``dt`` or that uses the Euler update.

    SUMO's defaults are a 1 s step and the semi-implicit Euler position update; a configuration
    must say ``<step-length value="dt"/>`` and ``<step-method.ballistic value="true"/>``
    (Euler is off from the ballistic update by ~2e-2 m/s² in acceleration for the same
    commanded speeds).

    Parameters
    ----------
    sumocfg : str or path-like
        The SUMO configuration file.
    dt : float
        The step (s) it must declare.

    Raises
    ------
    StringStabError
        A missing or unreadable file, a step that differs from ``dt``, or no ballistic update.
    """
    path = Path(sumocfg)
    root = read_xml(path, "--sumocfg", "a SUMO configuration file", "a SUMO configuration (XML)")
    values = {el.tag: el.get("value") for el in root.iter()}
    step = float(values.get("step-length") or 1.0)
    if abs(step - dt) > 1e-9 * max(1.0, dt):
        raise StringStabError(
            f"--sumocfg {path}: its step-length is {step:g} s but the controller's step is "
            f"{dt:g} s; expected <step-length value=\"{dt:g}\"/> (the certificate and the "
            "exact lag hold at one step)")
    if not _truthy(values.get("step-method.ballistic")):
        raise StringStabError(
            f"--sumocfg {path}: uses SUMO's Euler position update; expected "
            "<step-method.ballistic value=\"true\"/> (Euler differs from the commanded motion "
            "by ~2e-2 m/s^2 in acceleration)")


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _socket_inodes(pid: int) -> set[str]:
    out = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        with contextlib.suppress(OSError):
            link = os.readlink(fd)
            if link.startswith("socket:["):
                out.add(link[8:-1])
    return out


def _tcp_rows() -> list[list[str]]:
    rows = []
    for name in ("/proc/net/tcp", "/proc/net/tcp6"):
        with contextlib.suppress(OSError), open(name, encoding="ascii") as f:
            rows += [line.split() for line in f.readlines()[1:]]
    return rows


def _wait_listening(port: int, proc: subprocess.Popen[bytes], timeout: float = 30.0) -> None:
    """Wait until SUMO listens on ``port`` (Linux: read /proc; elsewhere a short pause)."""
    if not Path("/proc/net/tcp").exists():
        time.sleep(0.2)
        return
    hexport = f"{port:04X}"
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if proc.poll() is not None:
            return  # it died: the connection attempt reports it
        if any(r[1].endswith(":" + hexport) and r[3] == "0A" for r in _tcp_rows()):
            return
        time.sleep(0.01)


def _check_peer(proc: subprocess.Popen[bytes], conn: Any) -> None:
    """Linux: SUMO's only TCP socket must be its connection to this process on 127.0.0.1."""
    if not Path(f"/proc/{proc.pid}/fd").exists():
        return
    conn.getVersion()  # a round trip: SUMO has accepted its client
    mine = conn._socket.getsockname()  # the client side of the one connection
    local = f"0100007F:{mine[1]:04X}"
    end = time.monotonic() + 5.0
    while True:
        theirs = _socket_inodes(proc.pid)
        rows = [r for r in _tcp_rows() if r[9] in theirs]
        ok = len(rows) == 1 and rows[0][2] == local and rows[0][3] == "01"
        if ok or time.monotonic() > end:
            break
        time.sleep(0.01)  # the listening socket is closed just after the accept
    if not ok:
        raise StringStabError(
            "SUMO's TraCI server did not end up connected to this process alone on 127.0.0.1 "
            f"(its sockets: {[(r[1], r[2], r[3]) for r in rows]}); stopped it")


class SumoSession:
    """A running SUMO simulation, stopped by :meth:`close` (use it as a context manager).

    Parameters
    ----------
    args : list of str
        SUMO options (``-n net -r routes`` or ``-c cfg``), without the binary, the step and the
        step method, which the session adds.
    dt : float
        The step, s (``--step-length``).
    api : {"libsumo", "traci"}
        In-process libsumo (default; one per process) or the TraCI protocol to a subprocess.
    scenario : bool
        A user's scenario: only the step, the ballistic update and quiet logs are imposed (the
        generated road also turns SUMO's collision handling and teleports off).

    Attributes
    ----------
    vehicle, simulation : module-like
        The SUMO API's domains (``libsumo.vehicle`` or a TraCI connection's).
    proc : subprocess.Popen or None
        The SUMO subprocess (TraCI only).
    """

    def __init__(self, args: list[str], *, dt: float, api: str = "libsumo",
                 scenario: bool = False) -> None:
        self.api = api
        self.dt = float(dt)
        self.proc: subprocess.Popen[bytes] | None = None
        self._conn: Any = None
        self._mod = import_api(api)
        cmd = [binary("sumo"), *args, "--step-length", repr(self.dt), "--step-method.ballistic",
               "true", "--no-step-log", "true", "--no-warnings", "true",
               "--duration-log.disable", "true"]
        if not scenario:  # the generated road: collisions are the toolkit's to count
            cmd += ["--collision.action", "none", "--collision.check-junctions", "false",
                    "--time-to-teleport", "-1", "--seed", "0"]
        self.cmd = cmd
        if api == "libsumo":
            if _ACTIVE_LIBSUMO:
                raise StringStabError(
                    "libsumo runs one simulation per process and one is open; close it first "
                    "(or use --api traci)")
            try:
                with contextlib.redirect_stdout(io.StringIO()):
                    self._mod.start(cmd)
            except Exception as e:
                with contextlib.suppress(Exception):
                    self._mod.close()
                raise StringStabError(f"SUMO did not start: {_one_line(e)}") from e
            _ACTIVE_LIBSUMO.append(self)
            self.vehicle, self.simulation = self._mod.vehicle, self._mod.simulation
            self._constants = self._mod.constants
        else:
            self._start_traci(cmd)
        try:
            check_running(self)
        except BaseException:
            self.close()
            raise

    def _start_traci(self, cmd: list[str]) -> None:
        traci = self._mod
        port = _free_port()
        self.proc = subprocess.Popen(
            [*cmd, "--remote-port", str(port), "--num-clients", "1"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        try:
            _wait_listening(port, self.proc)
            with contextlib.redirect_stdout(io.StringIO()):
                conn = traci.connect(port, numRetries=20, host="127.0.0.1", proc=self.proc,
                                     waitBetweenRetries=0.1)
            self._conn = conn
            _check_peer(self.proc, conn)
        except BaseException as e:
            self.close()
            if isinstance(e, StringStabError) or not isinstance(e, Exception):
                raise
            raise StringStabError(f"SUMO (TraCI) did not start: {_one_line(e)}{self._stderr()}") from e
        self.vehicle, self.simulation = conn.vehicle, conn.simulation
        self._constants = traci.constants

    def _stderr(self) -> str:
        if self.proc is None or self.proc.stderr is None or self.proc.poll() is None:
            return ""
        with contextlib.suppress(Exception):
            text = self.proc.stderr.read().decode(errors="replace").strip()
            if text:
                return "; SUMO said: " + " ".join(text.split())[:300]
        return ""

    @property
    def constants(self) -> Any:
        """The TraCI constants (variable ids for subscriptions)."""
        return self._constants

    def step(self) -> None:
        """Advance SUMO one step; a SUMO failure becomes a one-line :class:`StringStabError`."""
        try:
            if self._conn is not None:
                self._conn.simulationStep()
            else:
                self._mod.simulationStep()
        except Exception as e:
            raise StringStabError(f"SUMO stopped: {_one_line(e)}{self._stderr()}") from e

    def close(self) -> None:
        """Stop SUMO (idempotent): close libsumo, or the TraCI connection and its subprocess.

        The subprocess is the one this session started; it is killed after 10 s if it does not
        exit.
        """
        if self.api == "libsumo":
            if self in _ACTIVE_LIBSUMO:
                _ACTIVE_LIBSUMO.remove(self)
                with contextlib.suppress(Exception):
                    self._mod.close()
            return
        if self._conn is not None:
            conn, self._conn = self._conn, None
            with contextlib.suppress(Exception):
                conn.close(wait=False)
        if self.proc is not None:
            proc = self.proc
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
            finally:
                if proc.stderr is not None:
                    proc.stderr.close()

    def __enter__(self) -> SumoSession:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _one_line(e: BaseException) -> str:
    text = " ".join(str(e).split()) or type(e).__name__
    return text[:400]


def check_running(session: SumoSession) -> None:
    """Ask the running SUMO for its step and position update; refuse a mismatch.

    Parameters
    ----------
    session : SumoSession
        The open session (its ``dt`` is the expected step, s).

    Raises
    ------
    StringStabError
        If SUMO's step differs from the session's ``dt`` or it does not update positions
        ballistically.
    """
    got = float(session.simulation.getDeltaT())
    if abs(got - session.dt) > 1e-9 * max(1.0, session.dt):
        raise StringStabError(
            f"SUMO runs with a step of {got:g} s; expected the controller's step {session.dt:g} s")
    ballistic = session.simulation.getOption("step-method.ballistic")
    if not _truthy(ballistic):
        raise StringStabError(
            f"SUMO runs with the Euler position update (step-method.ballistic = {ballistic!r}); "
            "expected the ballistic update")
