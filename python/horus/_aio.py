"""asyncio for topics: `await topic.recv_async()` waits in a worker thread (the GIL released
there) in short slices, so a cancelled await stops waiting within 0.1 s."""

import asyncio

_SLICE = 0.1


async def recv_async(topic, timeout=None):
    """The next message; None when `timeout` seconds passed first (None: wait until one comes)."""
    loop = asyncio.get_running_loop()
    deadline = None if timeout is None else loop.time() + timeout
    while True:
        m = topic.recv()
        if m is not None:
            return m
        left = _SLICE if deadline is None else min(_SLICE, deadline - loop.time())
        if left <= 0:
            return None
        if await loop.run_in_executor(None, topic.wait_for, left):
            continue


async def aiter_topic(topic):
    """`async for msg in topic.aiter():` every message, as it comes."""
    while True:
        yield await recv_async(topic)
