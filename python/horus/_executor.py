"""horus.Executor: callbacks for topics and timers, run by the thread that spins, as C++'s
horus::Executor does it:

- callbacks of one executor never run at the same time (one thread spins at a time);
- a topic's messages are handled in order; a busy topic yields after 64, so topics and timers
  take turns;
- every(period, f) runs f at start + k * period; a call too late to keep up skips the missed
  ticks (counted in timer_overruns) rather than running them in a burst;
- stop() may be called from any thread or a signal handler: spin() returns after the callback
  running now;
- while it waits, the spinning thread sleeps in the kernel (a WaitSet), the GIL released.

Unlike C++ (which logs and counts it), an exception a callback raises ends spin() and is
raised by it, as rclpy does.
"""

import threading
import time

from ._horus import Topic, Trigger, WaitSet

_BATCH = 64
_SLICE = 0.1  # spin() checks stop and Python's signals this often


class Executor:
    def __init__(self):
        self._waitset = WaitSet()
        self._stop = Trigger()
        self._wake = Trigger()  # a timer or topic was added: a wait under way starts again
        self._waitset.attach(self._stop)
        self._waitset.attach(self._wake)
        self._lock = threading.Lock()  # the subscriptions and timers
        self._spinning = threading.Lock()  # one spinning thread at a time
        self._spinner = None  # the thread that spins now
        self._subscriptions = {}
        self._timers = {}
        self._next_id = 1
        self.callbacks_run = 0
        self.timer_overruns = 0

    def _new_id(self):
        with self._lock:
            i = self._next_id
            self._next_id += 1
            return i

    def subscribe(self, name, type, callback, **options):
        """Opens topic `name` of message class `type` (options as horus.Topic's) and calls
        callback(msg) for each message; the subscription's id."""
        topic = Topic(name, type, **options)
        self._waitset.attach(topic)
        sid = self._new_id()
        with self._lock:
            self._subscriptions[sid] = (topic, callback)
        self._stop_wait()
        return sid

    def every(self, period, callback):
        """Calls callback() every `period` seconds (> 0), first one period from now; the timer's id."""
        if not period > 0:
            raise ValueError(f"every: the period is seconds above 0 (got {period})")
        tid = self._new_id()
        with self._lock:
            self._timers[tid] = [float(period), time.monotonic() + period, callback]
        self._stop_wait()
        return tid

    def topic(self, ident):
        """The horus.Topic of subscription `ident` (its counts: dropped_count(), ...)."""
        with self._lock:
            return self._subscriptions[ident][0]

    def remove(self, ident):
        """Removes a subscription or a timer; False when there is none with this id."""
        with self._lock:
            if ident in self._timers:
                del self._timers[ident]
                return True
            sub = self._subscriptions.pop(ident, None)
        if sub is None:
            return False
        self._waitset.detach(sub[0])
        sub[0].close()
        return True

    def stop(self):
        """Makes spin() return after the callback running now (any thread, a signal handler)."""
        self._stop.fire()

    def spin(self, duration=None):
        """Runs callbacks until stop() (or for `duration` seconds). A stop() before spin()
        makes it return at once; each spin that returns for a stop clears it."""
        end = None if duration is None else time.monotonic() + duration
        with self._spin_guard():
            try:
                while not self._stop.fired:
                    left = _SLICE if end is None else min(_SLICE, end - time.monotonic())
                    if left <= 0:
                        return
                    self._spin_once(left)
            finally:
                if self._stop.fired:
                    self._stop.reset()

    def spin_once(self, timeout=0.0):
        """Waits up to `timeout` seconds for work, does what is ready; the callbacks run. A
        stop() not yet consumed is (nothing runs, 0)."""
        with self._spin_guard():
            if self._stop.fired:
                self._stop.reset()
                return 0
            return self._spin_once(timeout)

    def _spin_guard(self):
        if self._spinner == threading.get_ident():
            raise RuntimeError("Executor.spin: called from one of its own callbacks (it would wait for itself)")
        executor = self

        class Guard:
            def __enter__(self):
                executor._spinning.acquire()
                executor._spinner = threading.get_ident()

            def __exit__(self, *exc):
                executor._spinner = None
                executor._spinning.release()
        return Guard()

    def _stop_wait(self):
        self._wake.fire()

    def _spin_once(self, timeout):
        n = self._run_timers()
        with self._lock:
            next_timer = min((t[1] for t in self._timers.values()), default=None)
        wait = timeout
        if next_timer is not None:
            wait = max(0.0, min(wait, next_timer - time.monotonic()))
        ready = self._waitset.wait(wait if n == 0 else 0.0)
        if self._wake.fired:
            self._wake.reset()
        with self._lock:
            subs = [(sid, s) for sid, s in self._subscriptions.items() if s[0] in ready]
        for sid, (topic, callback) in subs:
            for _ in range(_BATCH):
                # stop() returns after the callback running now; remove() (maybe by a callback) ends one
                if self._stop.fired or sid not in self._subscriptions:
                    return n
                try:
                    msg = topic.recv()
                except ValueError:
                    if topic.closed:  # removed by another thread meanwhile
                        break
                    raise
                if msg is None:
                    break
                n += 1
                self.callbacks_run += 1
                callback(msg)
        return n if self._stop.fired else n + self._run_timers()

    def _run_timers(self):
        n = 0
        now = time.monotonic()
        with self._lock:
            due = [t for t in self._timers.values() if t[1] <= now]
        for t in due:
            if self._stop.fired:
                break
            period, nxt, callback = t
            late = int((now - nxt) // period)
            if late > 0:
                self.timer_overruns += late
            t[1] = nxt + (late + 1) * period
            n += 1
            self.callbacks_run += 1
            callback()
        return n
