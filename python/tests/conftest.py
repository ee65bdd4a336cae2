"""Shared fixtures of the Python tests (run by ctest: python/CMakeLists.txt sets PYTHONPATH to
the build tree and names the helper programs in the environment)."""

import os
import subprocess
import sys

import pytest

sys.path.insert(0, os.path.dirname(__file__))

# Shared memory of its own (tests of other programs run at the same time on this host: the
# fleet layer's own topics must not meet theirs), the C++ peers inheriting it; network tests
# stay on loopback, in a DDS domain of their own.
os.environ.setdefault("HORUS_NAMESPACE", f"pytest{os.getpid()}")
os.environ.setdefault("HORUS_DDS_LOCALHOST", "1")
os.environ.setdefault("HORUS_DOMAIN_ID", str(100 + os.getpid() % 100))
os.environ.setdefault("HORUS_LCM_URL", "udpm://239.255.76.67:7667?ttl=0")


def program(var):
    path = os.environ.get(var)
    if not path or not os.path.exists(path):
        pytest.skip(f"{var} is not set to a built program (run the tests through ctest)")
    return path


@pytest.fixture
def unique(request):
    """A topic-name prefix no other test (or run) uses."""
    name = request.node.name.replace("[", "_").replace("]", "").replace("-", "_").replace(".", "_")
    return f"pytest.p{os.getpid()}.{name}"


class Peer:
    """A C++ program started by a test: it runs until the test ends (its stdin closes)."""

    def __init__(self, args, env=None, ready="ready", timeout=30):
        full_env = dict(os.environ)
        full_env.update(env or {})
        self.proc = subprocess.Popen(args, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, env=full_env, text=True)
        if ready:
            line = self.proc.stdout.readline()
            if line.strip() != ready:
                self.close()
                raise RuntimeError(f"{args[0]} did not say '{ready}': {line!r} {self.proc.stderr.read()}")

    def close(self):
        if self.proc.poll() is None:
            try:
                self.proc.stdin.close()
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        for f in (self.proc.stdout, self.proc.stderr):
            f.close()


@pytest.fixture
def peer():
    started = []

    def start(args, **kw):
        p = Peer(args, **kw)
        started.append(p)
        return p

    yield start
    for p in started:
        p.close()
