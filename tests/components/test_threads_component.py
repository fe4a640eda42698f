"""The shipped ``threads`` component (``loadrt threads name1=...``)."""

from __future__ import annotations

import pytest

import halsdk


def test_threads_creates_up_to_three(hal):
    assert hal.loadrt("threads", "name1=base period1=250000 fp1=0",
                      "name2=servo period2=1000000") == ["threads"]
    assert [t.name for t in hal.threads()] == ["base", "servo"]
    assert not hal.thread("base").uses_fp
    assert hal.thread("servo").uses_fp
    assert hal.thread("servo").period == 1_000_000
    comp = hal.component("threads")
    assert comp.realtime and comp.ready
    assert hal.component("__servo").realtime


def test_threads_stay_after_unload_and_reload_adds_more(hal):
    hal.loadrt("threads", name1="servo", period1=1_000_000)
    hal.unloadrt("threads")
    assert hal.components("threads") == []
    assert [t.name for t in hal.threads()] == ["servo"]
    hal.loadrt("threads", name1="slow", period1=10_000_000)
    assert [t.name for t in hal.threads()] == ["servo", "slow"]
    hal.step(10)
    assert hal.thread("slow").cycles == 1 and hal.thread("servo").cycles == 10


@pytest.mark.parametrize("words,made", [
    ("", [("thread1", 1_000_000, True)]),
    ("name1=a", [("a", 1_000_000, True)]),
    ("period1=2000000 fp1=0", [("thread1", 2_000_000, False)]),
    ("name2=b", [("thread1", 1_000_000, True)]),
    ("period2=2000000", [("thread1", 1_000_000, True)]),
    ("name3=c period3=3000000", [("c", 3_000_000, True),
                                 ("thread1", 1_000_000, True)]),
    ("period1=0", []),
    ("name1=", []),
])
def test_threads_defaults_are_the_references(hal, words, made):
    hal.loadrt("threads", words) if words else hal.loadrt("threads")
    assert sorted((t.name, t.period, t.uses_fp)
                  for t in hal.threads()) == made
    assert hal.component("threads").ready


@pytest.mark.parametrize("words,match", [
    ("name1=a period1=1000000 name2=b period2=1000", "fastest to slowest"),
    ("name1=a period1=10", "period"),
])
def test_threads_errors_leave_nothing(hal, words, match):
    with pytest.raises(halsdk.HalError, match=match):
        hal.loadrt("threads", words)
    assert hal.threads() == [] and hal.components() == []


def test_duplicate_thread_undoes_the_load(hal):
    hal.loadrt("threads", name1="a", period1=1_000_000)
    hal.unloadrt("threads")
    with pytest.raises(halsdk.ExistsError, match="'a'"):
        hal.loadrt("threads", "name1=b period1=1000000 name2=a "
                              "period2=2000000")
    assert [t.name for t in hal.threads()] == ["a"]
    assert hal.components("threads") == []


def test_a_threads_own_component_cannot_be_removed(hal):
    hal.newthread("servo", 1_000_000)
    with pytest.raises(halsdk.NotPermittedError, match="belongs to thread"):
        halsdk.core._core.comp_exit(hal.component("__servo").id)
    hal.step(1)
    assert hal.thread("servo").cycles == 1
    assert hal.pin("servo.time").owner == "__servo"
    hal.check()
