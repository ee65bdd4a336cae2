"""horus: typed zero-copy topics for robot fleets, from Python.

    import horus
    pub = horus.Topic("cmd_vel", horus.msg.CmdVel)
    sub = horus.Topic("cmd_vel", horus.msg.CmdVel)
    pub.send(horus.msg.CmdVel(linear=1.0, angular=0.5))
    print(sub.recv_for(1.0))

The same topics as C++ (shared memory on a host, DDS or LCM between hosts, chosen by scope,
backend, HORUS_BACKEND or the configuration file), the 81 standard messages as classes made
from the C++ reflection, images and clouds as NumPy arrays over the shared-memory pool.
"""

import sys

from . import _aio, _messages
from ._executor import Executor
from ._errors import (ConfigError, ConfigMismatchError, CorruptError, Error, InvalidArgumentError,
                      InvalidNameError, IoError, LimitReachedError, MessageTooLargeError,
                      TimeoutError, TypeMismatchError)
from ._horus import (Fleet, FleetEvent, FleetHost, FleetProcess, FleetTopic, Loan, Topic,
                     Trigger, WaitSet, __version__, config, message_types, msg, record)

# `from horus.msg import Pose2D`, `import horus.record`: the compiled submodules as modules.
for _name, _module in (("msg", msg), ("config", config), ("record", record)):
    sys.modules[f"{__name__}.{_name}"] = _module

_messages.install(message_types())
Topic.recv_async = _aio.recv_async
Topic.aiter = _aio.aiter_topic

__all__ = [
    "Topic", "Loan", "WaitSet", "Trigger", "Executor", "Fleet", "FleetHost", "FleetTopic",
    "FleetProcess", "FleetEvent", "msg", "config", "record", "message_types", "__version__",
    "Error", "InvalidNameError", "TypeMismatchError", "InvalidArgumentError", "ConfigMismatchError",
    "LimitReachedError", "TimeoutError", "MessageTooLargeError", "ConfigError", "IoError",
    "CorruptError",
]
