"""halsdk.driverkit.signals: SIGTERM/SIGINT as a flag, never a lock."""

from __future__ import annotations

import os
import signal
import threading

from halsdk.driverkit.signals import StopSignals


def test_signals_set_the_flag_and_the_handlers_come_back():
    before = signal.getsignal(signal.SIGTERM)
    with StopSignals() as stop:
        assert stop.caught == 0
        os.kill(os.getpid(), signal.SIGTERM)
        os.kill(os.getpid(), signal.SIGTERM)    # twice, as at a host death
        assert stop.caught == signal.SIGTERM
    assert signal.getsignal(signal.SIGTERM) is before


def test_a_signal_during_an_event_wait_does_not_deadlock():
    """The handler runs while the main thread waits on an Event (the
    drivers' loops did): it must not take that Event's lock."""
    ev = threading.Event()
    timer = threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT))
    with StopSignals() as stop:
        timer.start()
        while not stop.caught:
            ev.wait(0.01)
    timer.join()
    assert stop.caught == signal.SIGINT


def test_disabled_or_off_the_main_thread_it_does_nothing():
    before = signal.getsignal(signal.SIGTERM)
    with StopSignals(enabled=False):
        assert signal.getsignal(signal.SIGTERM) is before
    seen = []

    def other():
        with StopSignals():
            seen.append(signal.getsignal(signal.SIGTERM))
    t = threading.Thread(target=other)
    t.start()
    t.join()
    assert seen == [before]
