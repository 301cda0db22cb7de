"""Shared fixtures of the gonio package tests.

* ``corpus``: the photometric corpus, ``$GONIO_CORPUS`` or ``<repo>/../shared/data/photometry``;
  tests that need it are skipped with a visible reason when it is missing.
* ``gonio_bin``: the CLI binary, ``$GONIO_BIN`` or ``<repo>/target/{release,debug}/gonio``
  (``scripts/test-python.sh`` builds it); skipped visibly when missing.
"""

import os
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


def corpus_dir():
    env = os.environ.get("GONIO_CORPUS")
    candidates = [pathlib.Path(env)] if env else []
    candidates.append(REPO.parent / "shared" / "data" / "photometry")
    for c in candidates:
        if c.is_dir():
            return c
    return None


def corpus_files():
    c = corpus_dir()
    if c is None:
        return []
    return sorted(p for p in c.rglob("*") if p.suffix.lower() in (".ies", ".ldt"))


def valid_corpus_files():
    return [p for p in corpus_files() if not p.name.startswith("invalid_")]


@pytest.fixture(scope="session")
def corpus():
    c = corpus_dir()
    if c is None:
        pytest.skip("SKIPPED: photometric corpus not found (set GONIO_CORPUS)")
    return c


def corpus_params(valid_only=True):
    """Parameters for tests over the corpus: one per file, or one skipped placeholder."""
    files = valid_corpus_files() if valid_only else corpus_files()
    if not files:
        return [
            pytest.param(
                None,
                marks=pytest.mark.skip(reason="SKIPPED: photometric corpus not found (set GONIO_CORPUS)"),
                id="no-corpus",
            )
        ]
    return [pytest.param(p, id=p.name) for p in files]


@pytest.fixture(scope="session")
def gonio_bin():
    env = os.environ.get("GONIO_BIN")
    candidates = [pathlib.Path(env)] if env else []
    candidates += [REPO / "target" / "release" / "gonio", REPO / "target" / "debug" / "gonio"]
    for c in candidates:
        if c.is_file() and os.access(c, os.X_OK):
            return c
    pytest.skip("SKIPPED: the gonio CLI binary was not found (set GONIO_BIN or run cargo build -p gonio-cli)")


# Lines that tests want printed in the summary at the end of the run (Mitsuba's verdicts).
SUMMARY = []


def pytest_terminal_summary(terminalreporter):
    if SUMMARY:
        terminalreporter.section("gonio: Mitsuba chi-square harness")
        for line in SUMMARY:
            terminalreporter.write_line(line)
