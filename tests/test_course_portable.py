"""make test-portable's driver: every setting runs, and each failure is named beside its setting."""

from __future__ import annotations

import io
import sys

import pytest

from meshvae_lib.course.commands import main
from meshvae_lib.course.portable import parse_setting, run_settings, summary

# a stand-in for pytest: fails one "cell" when KERNELS=old, two when KERNELS=new and exits 3 when
# BROKEN is set, printing pytest's short-summary lines
FAKE = ("import os, sys\n"
        "k = os.environ.get('KERNELS', '')\n"
        "bad = {'old': ['nb/00.ipynb::Cell 15'], 'new': ['nb/00.ipynb::Cell 15', 'nb/02.ipynb::Cell 4']}.get(k, [])\n"
        "print('running under', k or 'default')\n"
        "for node in bad: print(f'FAILED {node} - mismatch')\n"
        "sys.exit(3 if os.environ.get('BROKEN') else 1 if bad else 0)\n")


def test_parse_setting_reads_shell_words_of_assignments():
    assert parse_setting("A=1 B=x,y") == {"A": "1", "B": "x,y"}
    assert parse_setting("EMPTY= C='a b'") == {"EMPTY": "", "C": "a b"}
    for bad in ["", "A", "1A=2", "A=1 bash"]:
        with pytest.raises(ValueError):
            parse_setting(bad)


def test_every_setting_runs_and_each_failure_is_named_beside_its_setting(tmp_path):
    out = io.StringIO()
    settings = ["KERNELS=old", "KERNELS=new MORE=1", "KERNELS=same", "BROKEN=1"]
    results = run_settings(settings, [sys.executable, "-c", FAKE], tmp_path / "logs", out=out)
    assert [r.returncode for r in results] == [1, 1, 0, 3]       # the first failure did not stop the rest
    assert results[0].failed == ["nb/00.ipynb::Cell 15"]
    assert results[1].failed == ["nb/00.ipynb::Cell 15", "nb/02.ipynb::Cell 4"]
    assert results[2].ok and results[2].failed == [] and not results[3].ok
    assert "running under new" in (tmp_path / "logs" / "setting-2.log").read_text()   # one log per setting
    assert "FAILED nb/02.ipynb::Cell 4" in out.getvalue()                              # and echoed as it runs
    text = summary(results)
    assert text.splitlines()[0] == "== portability pass: 4 setting(s), 3 with failures"
    block = text.split("FAIL KERNELS=new MORE=1: 2 failed")[1].split("\n")
    assert block[1].strip() == "nb/00.ipynb::Cell 15" and block[2].strip() == "nb/02.ipynb::Cell 4"
    assert "ok   KERNELS=same: passed" in text and "FAIL BROKEN=1: exit status 3" in text


def test_a_bad_setting_is_refused_before_anything_runs(tmp_path):
    with pytest.raises(ValueError, match="not an environment assignment"):
        run_settings(["KERNELS=old", "oops"], [sys.executable, "-c", FAKE], tmp_path)
    assert not list(tmp_path.glob("setting-*.log"))


def test_the_command_line_fails_when_any_setting_fails(tmp_path, capsys):
    command = f'"{sys.executable}" -c "import os, sys; sys.exit(os.environ[\'X\'] == \'2\')"'
    assert main(["portable", "--logs", str(tmp_path), "--command", command, "X=1", "X=2"]) == 1
    assert "FAIL X=2: exit status 1" in capsys.readouterr().out
    assert main(["portable", "--logs", str(tmp_path), "--command", command, "X=1"]) == 0


def test_output_without_a_last_newline_and_odd_bytes_is_still_read(tmp_path):
    script = "import sys; sys.stdout.buffer.write(b'..\\xff.\\nFAILED nb/03.ipynb::Cell 2 - x'); sys.exit(1)"
    out = io.StringIO()
    (result,) = run_settings(["A=1"], [sys.executable, "-c", script], tmp_path, out=out)
    assert result.failed == ["nb/03.ipynb::Cell 2"] and out.getvalue().startswith("== [1/1]")
    assert "..\ufffd.\n" in out.getvalue()
