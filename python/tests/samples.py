"""A message of every standard type with a distinct value in every field (as the C++ tests'
sample<T>()), made through the Python attributes only."""

import horus

LARGE = {
    "Image": lambda: horus.msg.Image(3, 5, horus.msg.ImageEncoding.Rgb8),
    "DepthImage": lambda: horus.msg.DepthImage(4, 6, horus.msg.TensorDtype.U16),
    "PointCloud": lambda: horus.msg.PointCloud(7, 4, horus.msg.TensorDtype.F32),
    "Tensor": lambda: horus.msg.Tensor([2, 3, 4], horus.msg.TensorDtype.U16),
}


class Filler:
    def __init__(self):
        self.k = 1

    def next(self):
        self.k += 1
        return self.k

    def number(self, kind):
        k = self.next()
        return (k % 1000) * 0.5 + 0.25 if kind == "f" else k % 100 + 1

    def fill(self, m):
        for name in type(m).fields:
            cur = getattr(m, name)
            if hasattr(type(cur), "__members__"):  # a horus.msg enum
                members = list(type(cur).__members__.values())
                setattr(m, name, members[self.next() % len(members)])
            elif hasattr(cur, "fields"):  # a nested message (a view)
                self.fill(cur)
            elif isinstance(cur, bool):
                setattr(m, name, self.next() % 2 == 1)
            elif isinstance(cur, (int, float)):
                setattr(m, name, self.number("f" if isinstance(cur, float) else "i"))
            elif isinstance(cur, str):
                self.text(m, name)
            elif hasattr(cur, "dtype"):  # fixed array (a writable view) or vector (a copy)
                values = [self.number(cur.dtype.kind) for _ in range(cur.size if cur.flags.writeable else 3)]
                setattr(m, name, [v % 2 == 1 for v in values] if cur.dtype.kind == "b" else values)
            elif isinstance(cur, tuple) and cur and hasattr(cur[0], "fields"):
                for element in cur:
                    self.fill(element)
            elif isinstance(cur, tuple):
                setattr(m, name, [f"t{self.next()}" for _ in cur])
        return m

    def text(self, m, name):
        for text in (f"t{self.next()}", "c"):
            try:
                setattr(m, name, text)
                return
            except (ValueError, TypeError):
                continue


def sample(cls):
    if cls.__name__ in LARGE:
        m = LARGE[cls.__name__]()
        assert m.data.flags.c_contiguous, f"{cls.__name__}: a new message's bytes are contiguous"
        flat = m.data.reshape(-1).view("uint8")
        for i in range(flat.size):
            flat[i] = (i * 7 + 3) % 256
        if hasattr(m, "frame_id"):
            m.frame_id = "cam"
        if cls.__name__ != "Tensor":
            m.timestamp_ns = 42
        return m
    if cls.__name__ == "GenericMessage":
        return horus.msg.GenericMessage.from_value({"seq": 7, "pose": [1.5, -2.0], "name": "r1"}, "meta")
    return Filler().fill(cls())
