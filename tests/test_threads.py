"""MESHVAE_NUM_THREADS: the one switch that re-runs the course under another thread count."""

from __future__ import annotations

import pytest
import torch
from threadpoolctl import threadpool_info

from meshvae_lib.model.threads import ENV_VAR, configure_threads, threads_from_environment


def test_default_is_used_when_the_variable_is_unset_or_blank(monkeypatch):
    monkeypatch.delenv(ENV_VAR, raising=False)
    assert threads_from_environment(2) == 2
    monkeypatch.setenv(ENV_VAR, "  ")
    assert threads_from_environment(3) == 3


def test_variable_overrides_the_callers_count(monkeypatch):
    monkeypatch.setenv(ENV_VAR, "1")
    assert threads_from_environment(2) == 1


@pytest.mark.parametrize("raw", ["0", "-2", "two", "1.5"])
def test_bad_values_are_clear_errors(monkeypatch, raw):
    monkeypatch.setenv(ENV_VAR, raw)
    with pytest.raises(ValueError, match=f"{ENV_VAR} must be a positive integer, got '{raw}'"):
        threads_from_environment(2)


def test_bad_default_is_an_error(monkeypatch):
    monkeypatch.delenv(ENV_VAR, raising=False)
    with pytest.raises(ValueError, match="got 0"):
        threads_from_environment(0)


def test_configure_threads_sets_torch_and_blas(monkeypatch):
    before = torch.get_num_threads()
    monkeypatch.setenv(ENV_VAR, "1")
    try:
        assert configure_threads(2) == 1
        assert torch.get_num_threads() == 1
        assert all(p["num_threads"] == 1 for p in threadpool_info() if p["user_api"] == "blas")
    finally:
        monkeypatch.delenv(ENV_VAR)
        configure_threads(before)
    assert torch.get_num_threads() == before


def test_cli_reads_the_variable_and_reports_a_bad_value(monkeypatch, capsys):
    from meshvae_lib.cli import main

    monkeypatch.setenv(ENV_VAR, "zero")
    assert main(["synth", "--list"]) == 2   # a bad value: exit 2
    assert f"{ENV_VAR} must be a positive integer" in capsys.readouterr().err
