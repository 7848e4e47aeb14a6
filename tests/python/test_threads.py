"""A sweep releases the GIL while its trials run, and Ctrl-C (SIGINT) stops
it with KeyboardInterrupt, leaving no output files, only the journal a
resume continues from. Synchronised on events and on the sweep's own
progress calls, never on sleeps or elapsed time."""

import os
import signal
import sys
import threading

import pytest

import beamsim


@pytest.fixture
def no_preemption():
    """The GIL changes hands only when its holder releases it: Python's
    switch interval made longer than any test."""
    before = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    yield
    sys.setswitchinterval(before)


def test_another_thread_runs_during_a_sweep(h1, no_preemption):
    """The sweep calls progress(done, total) after each trial (one thread).
    The first call wakes a Python thread; with no preemption it can run
    only when the sweep releases the GIL, so the number of calls it sees
    must be below the last one's. A sweep that held the GIL would let it run
    only after returning, when every call has been made."""
    calls, seen = [], []
    woken = threading.Event()

    def other():
        woken.wait()
        seen.append(len(calls))

    def progress(done, total):
        calls.append(done)
        woken.set()

    t = threading.Thread(target=other, daemon=True)  # a sweep that raises leaves it waiting
    t.start()
    beamsim.sweep(h1, trials=4, threads=1, progress=progress)
    t.join()
    assert calls[-1] == 30 * 4
    assert seen and seen[0] < len(calls)


def interrupt_at_first(calls):
    """A progress callable that notes each call in calls and sends this
    process SIGINT (Ctrl-C) at the first."""
    def progress(done, total):
        calls.append(done)
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)
    return progress


def test_ctrl_c_stops_a_sweep(h1, tmp_path):
    calls = []
    progress = interrupt_at_first(calls)
    out = tmp_path / "s"
    with pytest.raises(KeyboardInterrupt):
        beamsim.sweep(h1, trials=4, threads=1, progress=progress, out=out)
    # Stopped at once: no more progress after the signal, no files, the
    # journal kept.
    assert calls == [1]
    assert not (out / "summary.json").exists() and not (out / "trials.csv").exists()
    assert (out / ".beamsim" / "journal").exists()
    # It continues where it stopped, to the uninterrupted sweep's numbers.
    r = beamsim.sweep(h1, trials=4, threads=1, out=out, resume=True)
    s = beamsim.sweep(h1, trials=4, threads=2)
    for k in s["trials"]:
        assert list(map(str, r["trials"][k])) == list(map(str, s["trials"][k])), k


def test_two_threads_one_out(h1, tmp_path):
    """Two sweeps into one directory from two threads of one process: the
    first holds it, the second is refused (ValueError naming it) at the
    first's first progress call, and the first still ends with all its
    trials, its staging area untouched by the refusal."""
    out = tmp_path / "d"
    refused = []

    def second():
        try:
            beamsim.sweep(h1, trials=2, threads=1, out=out)
        except ValueError as e:
            refused.append(str(e))

    def progress(done, total):
        if done == 1:
            t = threading.Thread(target=second)
            t.start()
            t.join()

    r = beamsim.sweep(h1, trials=4, threads=1, progress=progress, out=out)
    assert len(refused) == 1, refused
    assert str(out) in refused[0] and "another beamsim run" in refused[0]
    assert len(r["trials"]["trial"]) == 30 * 4
    assert (out / "manifest.json").exists() and not (out / ".beamsim").exists()


def test_finished_out_needs_overwrite(h1, tmp_path):
    """A finished sweep's directory is refused, naming it, and left as it
    was; overwrite=True replaces it."""
    out = tmp_path / "d"
    beamsim.sweep(h1, trials=2, threads=1, out=out)
    before = (out / "trials.csv").read_bytes()
    with pytest.raises(ValueError, match="holds the finished result of beamsim sweep") as e:
        beamsim.sweep(h1, trials=3, threads=1, out=out)
    assert "add overwrite=True to replace it" in str(e.value) and "--" not in str(e.value)
    assert (out / "trials.csv").read_bytes() == before
    r = beamsim.sweep(h1, trials=3, threads=1, out=out, overwrite=True)
    assert len(r["trials"]["trial"]) == 30 * 3
    c_out = tmp_path / "c"
    beamsim.compare(h1, trials=1, threads=1, out=c_out)
    with pytest.raises(ValueError, match="holds the finished result of beamsim compare"):
        beamsim.compare(h1, trials=1, threads=1, out=c_out)
    c = beamsim.compare(h1, trials=2, threads=1, out=c_out, overwrite=True)
    assert len(c["pairs"]["trial"]) == 30 * 2


def test_ctrl_c_stops_a_comparison_and_resume_continues(h1, tmp_path):
    """compare takes resume= as sweep does (it had none). Stopped by
    Ctrl-C, the comparison keeps its journal; resume=True continues it to
    the uninterrupted comparison's pairs.csv, byte for byte. The messages
    about resuming name resume=True, the argument, not the command line's
    --resume."""
    calls = []
    progress = interrupt_at_first(calls)
    out = tmp_path / "c"
    with pytest.raises(KeyboardInterrupt):
        beamsim.compare(h1, trials=2, threads=1, progress=progress, out=out)
    assert calls == [1]
    assert not (out / "pairs.csv").exists() and (out / ".beamsim" / "journal").exists()
    with pytest.raises(ValueError) as e:
        beamsim.compare(h1, trials=2, threads=1, out=out)
    assert "that run's command with resume=True continues it, overwrite=True discards it" \
        in str(e.value) and "--" not in str(e.value)
    beamsim.compare(h1, trials=2, threads=1, out=out, resume=True)
    whole = tmp_path / "whole"
    beamsim.compare(h1, trials=2, threads=2, out=whole)
    assert (out / "pairs.csv").read_bytes() == (whole / "pairs.csv").read_bytes()
    for call in (beamsim.compare, beamsim.sweep):
        with pytest.raises(ValueError) as e:
            call(h1, trials=2, out=out, resume=True)
        assert str(e.value).startswith(f"resume=True: {out} holds a finished run, nothing to "
                                       "resume (use overwrite=True instead") and \
            "--resume" not in str(e.value), str(e.value)
