"""The Python side of the message classes (horus.msg.*): the keyword constructor, __repr__ and
from_dict, over the field attributes the compiled module makes from the C++ reflection."""

import math
import reprlib

_repr = reprlib.Repr()
_repr.maxlist = 8
_repr.maxtuple = 8
_repr.maxstring = 60


def _field_repr(v):
    if hasattr(v, "fields"):
        return repr(v)
    if hasattr(v, "tolist") and getattr(v, "size", 0) > 8:
        return _repr.repr(v.tolist())
    if isinstance(v, tuple):
        return _repr.repr(v)
    return repr(v)


def _message_repr(self):
    cls = type(self)
    if cls.large_data:
        shape = "x".join(str(d) for d in self.data.shape)
        return f"{cls.__name__}({shape} {self.data.dtype}, {self.data.nbytes} bytes)"
    return f"{cls.__name__}(" + ", ".join(f"{f}={_field_repr(getattr(self, f))}" for f in cls.fields) + ")"


def _fill(obj, values, path):
    cls = type(obj)
    if not isinstance(values, dict):
        raise ValueError(f"{path}: expected a dict of {cls.__name__}'s fields, got {type(values).__name__}")
    for key, value in values.items():
        if key not in cls.fields:
            raise ValueError(f"{path}: {cls.__name__} has no field '{key}'; its fields: {', '.join(cls.fields)}")
        where = f"{path}.{key}"
        current = getattr(obj, key)
        if hasattr(current, "fields"):  # a nested message: a view into obj
            _fill(current, value, where)
        elif isinstance(current, tuple) and current and hasattr(current[0], "fields"):
            if not isinstance(value, (list, tuple)) or len(value) != len(current):
                raise ValueError(f"{where}: expected a list of {len(current)} dicts")
            for i, (element, v) in enumerate(zip(current, value)):
                _fill(element, v, f"{where}[{i}]")
        elif value is None and isinstance(current, float):
            setattr(obj, key, math.nan)  # to_dict renders a non-finite float as None (JSON null)
        elif isinstance(value, list) and hasattr(current, "dtype") and current.dtype.kind == "f":
            setattr(obj, key, [math.nan if v is None else v for v in value])
        else:
            setattr(obj, key, value)


def _from_dict(cls):
    def from_dict(values):
        """The message a dict (to_dict's) describes; ValueError names a wrong field."""
        if cls.large_data:
            return cls._from_dict(values)
        obj = cls()
        _fill(obj, values, cls.__name__)
        return obj
    return staticmethod(from_dict)


def _keyword_init(cls):
    base_init = cls.__init__

    def __init__(self, *args, **fields):
        base_init(self, *args)
        for key, value in fields.items():
            if key not in cls.fields:
                raise TypeError(f"{cls.__name__} has no field '{key}'; its fields: {', '.join(cls.fields)}")
            setattr(self, key, value)

    __init__.__doc__ = f"{cls.__name__}(**fields): every field defaults to zero ({', '.join(cls.fields)})"
    return __init__


def install(classes):
    for cls in classes:
        cls.__repr__ = _message_repr
        cls.from_dict = _from_dict(cls)
        if not cls.large_data:
            cls.__init__ = _keyword_init(cls)
