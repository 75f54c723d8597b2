"""The portability pass (``make test-portable``): one test command under several float settings.

A *setting* is a line of environment assignments, ``"OPENBLAS_CORETYPE=Haswell MESHVAE_NUM_THREADS=1"``,
that makes this machine compute as another one would (other BLAS kernels, other SIMD paths, one
thread). :func:`run_settings` runs the command (pytest over the notebooks, against their stored
outputs) once under each setting, every setting even when an earlier one fails, keeps each run's
output in a log file, and :func:`summary` names the failed tests beside the setting they failed
under. The Makefile lists the settings (``PORTABLE_SETTINGS``); README, "The portability pass",
says what each changes.
"""

from __future__ import annotations

import codecs
import os
import re
import shlex
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["parse_setting", "SettingResult", "run_settings", "summary"]

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
#: pytest's short summary lines of a failed test: "FAILED node - message", "ERROR node - message"
#: (nbval's node ids hold a space: "notebooks/00_tour.ipynb::Cell 15").
_FAILED = re.compile(r"^(FAILED|ERROR) (.+?)(?: - .*)?$")
_COLOUR = re.compile(r"\x1b\[[0-9;]*m")


def parse_setting(setting: str) -> dict[str, str]:
    """``"A=1 B=x,y"`` -> ``{"A": "1", "B": "x,y"}`` (shell words, each ``NAME=VALUE``)."""
    env = {}
    words = shlex.split(setting)
    if not words:
        raise ValueError("a setting needs at least one NAME=VALUE")
    for word in words:
        name, sep, value = word.partition("=")
        if not sep or not _NAME.fullmatch(name):
            raise ValueError(f"not an environment assignment NAME=VALUE: {word!r} (in {setting!r})")
        env[name] = value
    return env


@dataclass
class SettingResult:
    """One run of the command: the setting, its exit status, the failed test ids (pytest's
    ``FAILED``/``ERROR`` lines), the log file and the wall-clock seconds."""

    setting: str
    returncode: int
    failed: list[str] = field(default_factory=list)
    log: Path | None = None
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        return self.returncode == 0


def run_settings(settings: list[str], command: list[str], log_dir, out=None) -> list[SettingResult]:
    """Run ``command`` once under each setting (the current environment plus the setting's
    assignments), in order, all of them whatever the earlier ones returned.

    settings : lines of ``NAME=VALUE`` words (:func:`parse_setting`; all are checked before the first
    run); command : the argument list to run; log_dir : folder for ``setting-N.log`` (created,
    earlier logs there replaced); out : where to echo the command's output as it comes (default
    sys.stdout). Returns one :class:`SettingResult` per setting.
    """
    envs = [parse_setting(s) for s in settings]
    if not command:
        raise ValueError("no command to run")
    out = out or sys.stdout
    log_dir = Path(log_dir)
    log_dir.mkdir(parents=True, exist_ok=True)
    for old in log_dir.glob("setting-*.log"):
        old.unlink()
    results = []
    for k, (setting, extra) in enumerate(zip(settings, envs), start=1):
        print(f"== [{k}/{len(settings)}] {' '.join(command[:3])} ... under {setting}", file=out, flush=True)
        log = log_dir / f"setting-{k}.log"
        start = time.perf_counter()
        failed = []
        with open(log, "w") as fh:
            fh.write(f"# setting: {setting}\n# command: {shlex.join(command)}\n")
            proc = subprocess.Popen(command, env={**os.environ, **extra}, stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT)
            decoder = codecs.getincrementaldecoder("utf-8")(errors="replace")
            pending = ""
            while True:  # echo as it comes (pytest's progress dots end no line), parse whole lines
                chunk = proc.stdout.read1(65536)
                text = decoder.decode(chunk, final=not chunk)
                out.write(text)
                out.flush()
                fh.write(text)
                fh.flush()
                pending += text
                *lines, pending = pending.split("\n")
                if not chunk:
                    lines.append(pending)
                for line in lines:
                    m = _FAILED.match(_COLOUR.sub("", line))
                    if m and m.group(2) not in failed:
                        failed.append(m.group(2))
                if not chunk:
                    break
            returncode = proc.wait()
        results.append(SettingResult(setting, returncode, failed, log, time.perf_counter() - start))
    return results


def summary(results: list[SettingResult]) -> str:
    """A few lines: each setting, passed or what failed under it (test ids, or the exit status when
    none was named), its time and its log."""
    bad = [r for r in results if not r.ok]
    lines = [f"== portability pass: {len(results)} setting(s), "
             + (f"{len(bad)} with failures" if bad else "all passed")]
    for r in results:
        state = "passed" if r.ok else (f"{len(r.failed)} failed" if r.failed else f"exit status {r.returncode}")
        lines.append(f"{'ok  ' if r.ok else 'FAIL'} {r.setting}: {state} ({r.seconds:.0f} s, log {r.log})")
        lines.extend(f"       {node}" for node in r.failed)
    return "\n".join(lines)
