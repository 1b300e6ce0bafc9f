"""Process supervision: start every process, prefix and log its output, report deaths, respawn,
and stop everything in reverse order (SIGINT, then SIGTERM, then SIGKILL, with timeouts).

``respawn=True`` restarts a process that *dies* (non-zero exit code or a signal) while the launch
runs; a process that ends with exit code 0 has finished its work and is not restarted (so a
launch of nodes that end by themselves ends too).

A process ended *cleanly* when it exited with code 0 by itself, or when it stopped within the
SIGINT timeout once the launch asked it to (exit code 0, or killed by that SIGINT). A process
that needed SIGTERM or SIGKILL, or died with another code, did not; the launch's exit code is 0
only when every process ended cleanly.

The supervisor is a caller of the graph host (:mod:`mindgrasp_ros.graph.host`): each process is
a :class:`~mindgrasp_ros.graph.host.ProcessHandle` of the ``Processes`` scheduler, which polls
them; a process has ended when its ``done`` future has (:func:`~mindgrasp_ros.node_main.is_done`,
as for every node of every graph host), and the launch stops them in the graph host's shutdown
order (:func:`~mindgrasp_ros.node_main.end_graph`: newest first). What is the launch's own: the
command lines, the prefixed output, respawn, ``required``, ``on_exit=Shutdown()`` and the
SIGINT/SIGTERM/SIGKILL stages with their timeouts.
"""

from __future__ import annotations

import collections
import concurrent.futures
import contextlib
import ctypes
import logging
import os
import re
import shlex
import signal
import subprocess
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

from mindgrasp_launch.actions.execute_process import ProcessSpec
from mindgrasp_launch.output import Printer
from mindgrasp_ros.graph.host import GraphRunner, Processes
from mindgrasp_ros.node_main import is_done

logger = logging.getLogger('launch')

TAIL_LINES = 20
_CLEAN_ON_SIGINT = (0, -signal.SIGINT, 128 + signal.SIGINT)
#: a ROS log line: [LEVEL] [stamp] [logger.name]: message (rcutils' default format)
_LOG_LINE = re.compile(r'^\[[A-Z]+\] \[[0-9.]+\] \[([^\]]+)\]: ')

try:  # children get SIGTERM if the launcher itself is killed (Linux)
    _LIBC = ctypes.CDLL(None, use_errno=True)
    _PR_SET_PDEATHSIG = 1
except OSError:  # pragma: no cover - not Linux
    _LIBC = None


def _child_setup() -> None:
    if _LIBC is not None:
        _LIBC.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
        # a launcher started in the background (`&`, nohup) ignores SIGINT, and exec keeps
        # ignored signals ignored: give the nodes the default so that SIGINT reaches rclpy
        _LIBC.signal(signal.SIGINT, 0)   # SIG_DFL
        _LIBC.signal(signal.SIGTERM, 0)


def describe_exit(returncode: int) -> str:
    """'exit code 3' or 'killed by signal SIGSEGV (-11)'."""
    if returncode < 0:
        try:
            name = signal.Signals(-returncode).name
        except ValueError:
            name = f'signal {-returncode}'
        return f'killed by signal {name} ({returncode})'
    return f'exit code {returncode}'


@dataclass
class ProcessResult:
    """How one process of the launch ended."""

    label: str
    returncode: int | None
    clean: bool
    how: str            #: 'finished', 'died', 'stopped by SIGINT', '... SIGTERM', '... SIGKILL'
    restarts: int
    pid: int | None
    log: str


@dataclass
class ManagedProcess:
    """A :class:`ProcessSpec` with its running OS process, log file and last lines."""

    spec: ProcessSpec
    command: list[str]
    log_path: Path
    env: dict[str, str]
    popen: subprocess.Popen | None = None
    restarts: int = 0
    tail: collections.deque = field(default_factory=lambda: collections.deque(maxlen=TAIL_LINES))
    readers: list[threading.Thread] = field(default_factory=list)
    log_file: IO[str] | None = None
    restart_at: float | None = None
    returncode: int | None = None
    stop_stage: str | None = None
    how: str = 'not started'
    clean: bool = True
    lock: threading.Lock = field(default_factory=threading.Lock)
    component_logs: dict[str, IO[str]] = field(default_factory=dict)
    #: completes with the exit code once the process ended for good (no respawn pending)
    done: concurrent.futures.Future = field(default_factory=concurrent.futures.Future)

    @property
    def running(self) -> bool:
        return self.popen is not None and self.returncode is None

    @property
    def label(self) -> str:
        return self.spec.label

    def settle(self) -> None:
        """Complete :attr:`done` once the process neither runs nor waits for a respawn."""
        if not self.running and self.restart_at is None and not self.done.done():
            self.done.set_result(self.returncode)


class _Hosted:
    """A launch's process as the graph host sees it (a ``ProcessHandle``): the supervisor
    starts it, looks for its end and stops it."""

    def __init__(self, supervisor: Supervisor, proc: ManagedProcess) -> None:
        self.supervisor = supervisor
        self.proc = proc

    @property
    def done(self) -> concurrent.futures.Future:
        return self.proc.done

    def get_name(self) -> str:
        return self.proc.label

    def start(self) -> None:
        self.supervisor.start(self.proc)

    def poll(self) -> None:
        self.supervisor.poll(self.proc)

    def destroy_node(self) -> None:
        self.supervisor.end(self.proc)


class Supervisor:
    """Runs a list of processes until they end, a signal, a death or ``duration`` seconds.

    Args:
        processes: what to start, in order (stopped in reverse order).
        log_dir: folder of the per-process log files ``<label>.log``.
        sigint_timeout: s a process gets to end after SIGINT before SIGTERM.
        sigterm_timeout: s after SIGTERM before SIGKILL.
        duration: s after which the launch ends by itself (None or <= 0: no limit).
        printer: terminal output (default: stdout/stderr).
        env: base environment of the processes (default: the launcher's).
    """

    def __init__(self, processes: Sequence[tuple[ProcessSpec, list[str]]], log_dir: Path, *,
                 sigint_timeout: float = 10.0, sigterm_timeout: float = 5.0,
                 duration: float | None = None, printer: Printer | None = None,
                 env: dict[str, str] | None = None) -> None:
        self.log_dir = Path(log_dir)
        self.sigint_timeout = float(sigint_timeout)
        self.sigterm_timeout = float(sigterm_timeout)
        self.duration = duration if duration and duration > 0 else None
        self.printer = printer or Printer()
        base_env = dict(os.environ if env is None else env)
        self.procs: list[ManagedProcess] = []
        for spec, command in processes:
            penv = dict(base_env if spec.env is None else spec.env)
            penv.update(spec.additional_env)
            penv.setdefault('PYTHONUNBUFFERED', '1')
            penv.setdefault('RCUTILS_COLORIZED_OUTPUT', '1' if self.printer.colour else '0')
            self.procs.append(ManagedProcess(spec=spec, command=command, env=penv,
                                             log_path=self.log_dir / f'{spec.label}.log'))
        self._stop_reason: str | None = None
        #: the signal (SIGINT, SIGTERM, SIGHUP) that ended the launch before its end, or None
        self.interrupted_by: int | None = None
        self._signals = 0
        self._started_at = 0.0
        self.on_started: Callable[[ManagedProcess], None] | None = None

    # -- requests (signal handlers, duration, deaths) ------------------------------------------
    def request_shutdown(self, reason: str) -> None:
        """Ask the main loop to stop every process (idempotent; the first reason is kept)."""
        if self._stop_reason is None:
            self._stop_reason = reason

    def _on_signal(self, signum: int, frame: object) -> None:
        self._signals += 1
        name = signal.Signals(signum).name
        if self._signals == 1:
            if self._stop_reason is None:
                self.interrupted_by = signum
            self.request_shutdown(f'{name} received')
        # a second signal: the stop loop escalates to the next stage at once

    # -- running -------------------------------------------------------------------------------
    def _start(self, proc: ManagedProcess) -> None:
        spec = proc.spec
        self.log_dir.mkdir(parents=True, exist_ok=True)
        if proc.log_file is None:
            proc.log_file = proc.log_path.open('a', encoding='utf-8')
        what = 'restarting' if proc.restarts else 'starting'
        line = proc.command[0] if spec.shell else shlex.join(proc.command)
        with contextlib.suppress(OSError, ValueError):
            proc.log_file.write(f'--- launch: {what} {line}\n')
            proc.log_file.flush()
        try:
            proc.popen = subprocess.Popen(
                proc.command[0] if spec.shell else proc.command, shell=spec.shell,
                cwd=spec.cwd, env=proc.env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                stderr=subprocess.PIPE, start_new_session=True, preexec_fn=_child_setup)
        except OSError as exc:
            proc.returncode = 127
            proc.how = f'could not start: {exc}'
            proc.clean = False
            logger.error("process '%s' could not start (%s): check the command %s.",
                         spec.label, exc, proc.command)
            self.request_shutdown(f"process '{spec.label}' could not start")
            return
        proc.returncode = None
        proc.stop_stage = None
        proc.how = 'running'
        proc.clean = False
        proc.readers = [
            threading.Thread(target=self._read, args=(proc, proc.popen.stdout, False),
                             daemon=True, name=f'read-{spec.label}-out'),
            threading.Thread(target=self._read, args=(proc, proc.popen.stderr, True),
                             daemon=True, name=f'read-{spec.label}-err'),
        ]
        for reader in proc.readers:
            reader.start()
        logger.info("process started with pid [%d]: %s", proc.popen.pid, spec.label)
        if self.on_started is not None:
            self.on_started(proc)

    def _read(self, proc: ManagedProcess, stream: IO[bytes], is_err: bool) -> None:
        show = proc.spec.output in ('screen', 'both')
        for raw in iter(stream.readline, b''):
            text = raw.decode('utf-8', errors='replace').rstrip('\r\n')
            with proc.lock:
                proc.tail.append(text)
                if proc.log_file is not None and not proc.log_file.closed:
                    try:
                        proc.log_file.write(text + '\n')
                        proc.log_file.flush()
                    except OSError as exc:  # disk full: keep draining the pipe, say it once
                        with contextlib.suppress(OSError):  # its buffer cannot be flushed
                            proc.log_file.close()
                        logger.error("cannot write the log of '%s' any more (%s); its output "
                                     "still goes to the terminal. Free disk space.",
                                     proc.label, exc)
            label = proc.label
            if proc.spec.logger_labels:  # composed: lines of a node's logger under its name
                match = _LOG_LINE.match(text)
                if match and match.group(1) in proc.spec.logger_labels:
                    label = proc.spec.logger_labels[match.group(1)]
                    self._component_log(proc, label, text)
            if show:
                self.printer.line(label, text, stderr=is_err)
        stream.close()

    def _component_log(self, proc: ManagedProcess, label: str, text: str) -> None:
        """Also write a composed node's lines to ``<label>.log``."""
        with proc.lock:
            handle = proc.component_logs.get(label)
            if handle is None:
                try:
                    handle = (self.log_dir / f'{label}.log').open('a', encoding='utf-8')
                except OSError:
                    return
                proc.component_logs[label] = handle
            with contextlib.suppress(OSError, ValueError):
                handle.write(text + '\n')
                handle.flush()

    def _collect(self, proc: ManagedProcess) -> None:
        """Wait for the output threads of an exited process so its tail is complete."""
        for reader in proc.readers:
            reader.join(timeout=2.0)

    def _report_tail(self, proc: ManagedProcess) -> str:
        with proc.lock:
            lines = list(proc.tail)
        if not lines:
            return f'(no output; log: {proc.log_path})'
        body = '\n'.join(f'    | {line}' for line in lines)
        return f'last {len(lines)} lines of {proc.log_path}:\n{body}'

    def _handle_exit(self, proc: ManagedProcess, now: float) -> None:
        rc = proc.popen.returncode  # type: ignore[union-attr]
        proc.returncode = rc
        self._collect(proc)
        spec = proc.spec
        if self._stop_reason is not None and proc.stop_stage is None:
            # ended while the launch was stopping, before its turn: fine if exit code 0
            proc.how = 'finished' if rc == 0 else 'died'
            proc.clean = rc == 0
            if rc != 0:
                logger.error("process '%s' (pid %d) died during shutdown: %s. %s", spec.label,
                             proc.popen.pid, describe_exit(rc), self._report_tail(proc))
            return
        if rc != 0 and spec.respawn and (spec.respawn_max_retries < 0
                                         or proc.restarts < spec.respawn_max_retries):
            logger.error("process '%s' (pid %d) died: %s; respawning in %.1f s (respawn=True, "
                         "restart %d). %s", spec.label, proc.popen.pid, describe_exit(rc),
                         spec.respawn_delay, proc.restarts + 1, self._report_tail(proc))
            proc.restart_at = now + spec.respawn_delay
            proc.how = 'respawning'
            return
        if rc == 0 and spec.required:
            proc.how, proc.clean = 'ended', False
            logger.error("required process '%s' (pid %d) ended (exit code 0) while the launch "
                         'was running; stopping every process.', spec.label, proc.popen.pid)
            self.request_shutdown(f"required process '{spec.label}' ended")
            return
        if rc == 0:
            proc.how, proc.clean = 'finished', True
            logger.info("process has finished cleanly [pid %d]: %s", proc.popen.pid, spec.label)
            if spec.shutdown_on_exit:
                self.request_shutdown(f"'{spec.label}' ended and has on_exit=Shutdown()")
            return
        proc.how, proc.clean = 'died', False
        logger.error("process '%s' (pid %d) died: %s. %s", spec.label, proc.popen.pid,
                     describe_exit(rc), self._report_tail(proc))
        self.request_shutdown(f"process '{spec.label}' died ({describe_exit(rc)})")

    def run(self) -> list[ProcessResult]:
        """Start, supervise and stop every process; returns how each ended."""
        handlers = {}
        if threading.current_thread() is threading.main_thread():
            for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
                handlers[signum] = signal.signal(signum, self._on_signal)
        try:
            self._started_at = time.monotonic()
            runner = GraphRunner(Processes(self.log_dir), log=logger.error)
            if not self.procs:
                self.request_shutdown('the launch description starts no process')
            for proc in self.procs:
                if self._stop_reason is not None:
                    break
                runner.add(_Hosted(self, proc))
            runner.spin_until(self._should_stop)
            self._shutdown(runner)
        finally:
            for signum, previous in handlers.items():
                signal.signal(signum, previous)
            for proc in self.procs:
                self._collect(proc)
                if proc.log_file is not None:
                    with proc.lock, contextlib.suppress(OSError):
                        proc.log_file.close()
                for handle in proc.component_logs.values():
                    with contextlib.suppress(OSError):
                        handle.close()
        return self.results()

    def start(self, proc: ManagedProcess) -> None:
        """Start ``proc`` (the graph host adds it)."""
        self._start(proc)
        proc.settle()                  # a process that could not start has ended

    def poll(self, proc: ManagedProcess) -> None:
        """The graph host's poll of ``proc``: its end, or its respawn when the delay is over."""
        now = time.monotonic()
        if proc.running and proc.popen.poll() is not None:  # type: ignore[union-attr]
            self._handle_exit(proc, now)
        if proc.restart_at is not None and now >= proc.restart_at \
                and self._stop_reason is None:
            proc.restart_at = None
            proc.restarts += 1
            self._start(proc)
        proc.settle()

    def _should_stop(self) -> bool:
        """The launch ends: a reason was given, its duration is over, or every process that is
        not a daemon (the recorder) has ended (:func:`is_done`)."""
        if self._stop_reason is None and self.duration is not None \
                and time.monotonic() - self._started_at >= self.duration:
            self.request_shutdown(f'duration of {self.duration:g} s reached')
        if self._stop_reason is None and any(not p.spec.daemon for p in self.procs) and all(
                is_done(p) for p in self.procs if not p.spec.daemon):
            self.request_shutdown('every node has ended')
        return self._stop_reason is not None

    def _wait(self, proc: ManagedProcess, timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        signals_seen = self._signals
        while time.monotonic() < deadline:
            if proc.popen.poll() is not None:  # type: ignore[union-attr]
                return True
            if self._signals > signals_seen:  # another Ctrl-C: escalate now
                return False
            time.sleep(0.02)
        return proc.popen.poll() is not None  # type: ignore[union-attr]

    def _signal(self, proc: ManagedProcess, signum: int) -> None:
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(proc.popen.pid, signum)  # type: ignore[union-attr]

    def _stop(self, proc: ManagedProcess) -> None:
        spec = proc.spec
        stages = ((signal.SIGINT, self.sigint_timeout if spec.sigterm_timeout is None
                   else spec.sigterm_timeout),
                  (signal.SIGTERM, self.sigterm_timeout if spec.sigkill_timeout is None
                   else spec.sigkill_timeout),
                  (signal.SIGKILL, 5.0))
        for signum, timeout in stages:
            proc.stop_stage = signum.name
            self._signal(proc, signum)
            if self._wait(proc, timeout):
                break
            if signum != signal.SIGKILL:
                nxt = 'SIGTERM' if signum == signal.SIGINT else 'SIGKILL'
                logger.warning("process '%s' (pid %d) did not stop %.1f s after %s; sending %s.",
                               spec.label, proc.popen.pid, timeout, signum.name, nxt)
        rc = proc.popen.wait()  # type: ignore[union-attr]
        proc.returncode = rc
        self._collect(proc)
        proc.how = f'stopped by {proc.stop_stage}'
        proc.clean = proc.stop_stage == 'SIGINT' and rc in _CLEAN_ON_SIGINT
        if proc.clean:
            logger.info("process has finished cleanly [pid %d]: %s", proc.popen.pid, spec.label)
        elif proc.stop_stage == 'SIGINT':
            logger.error("process '%s' (pid %d) failed while stopping: %s. %s", spec.label,
                         proc.popen.pid, describe_exit(rc), self._report_tail(proc))
        else:
            logger.error("process '%s' (pid %d) had to be stopped with %s (%s).", spec.label,
                         proc.popen.pid, proc.stop_stage, describe_exit(rc))

    def end(self, proc: ManagedProcess) -> None:
        """Stop ``proc`` unless it ended already (the graph host's ``destroy_node``)."""
        if proc.popen is not None:
            if proc.returncode is None and proc.popen.poll() is not None:
                self._handle_exit(proc, time.monotonic())
            elif proc.returncode is None:
                self._stop(proc)
        proc.settle()

    def _shutdown(self, runner: GraphRunner) -> None:
        reason = self._stop_reason or 'launch ended'
        logger.info('stopping the launch: %s.', reason)
        for proc in self.procs:
            proc.restart_at = None
        runner.close()   # the graph host's shutdown order: each started process, newest first

    @property
    def stop_reason(self) -> str | None:
        """Why the launch ended."""
        return self._stop_reason

    def results(self) -> list[ProcessResult]:
        """How each process ended (in start order)."""
        return [ProcessResult(label=p.label, returncode=p.returncode, clean=p.clean, how=p.how,
                              restarts=p.restarts, pid=None if p.popen is None else p.popen.pid,
                              log=str(p.log_path)) for p in self.procs]
