"""Werkzeug's server (`flask run`) without one epoll descriptor left behind per dropped request.

After every response Werkzeug's request handler drains the socket through a fresh
`selectors.DefaultSelector()` (an epoll descriptor) and closes it at the end of that block; when
the client reset the connection, the read there raises and the close is skipped. A selector is a
reference cycle (it and its `_SelectorMapping` point at each other), so such a one outlives its
request until the garbage collector runs, which an idle server may not do for a long time: a
storm of SSE opens cut by TCP resets left 20-40 `anon_inode:[eventpoll]` descriptors open
(issue 27). The handler here gets a selector whose mapping holds it weakly: no cycle, so it is
freed, and its descriptor closed, as soon as the handler's frame lets go of it.

Gunicorn (the production server) does not use this code path.
"""

from __future__ import annotations

import selectors
import types
import weakref


class _AcyclicSelector(selectors.DefaultSelector):
    def __init__(self) -> None:
        super().__init__()
        self._map = selectors._SelectorMapping(weakref.proxy(self))


def install() -> None:
    """Give werkzeug.serving the acyclic selector (idempotent); the rest of the process keeps its own."""
    from werkzeug import serving

    if getattr(serving.selectors, "DefaultSelector", None) is _AcyclicSelector:
        return
    shim = types.ModuleType("selectors")
    shim.__dict__.update(selectors.__dict__)
    shim.DefaultSelector = _AcyclicSelector
    serving.selectors = shim
