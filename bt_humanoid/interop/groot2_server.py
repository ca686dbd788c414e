"""A live monitor for Groot2: the running tree and its node statuses over ZeroMQ, in BehaviorTree.CPP's protocol.

What ``BT::Groot2Publisher`` does (``src/loggers/groot2_publisher.cpp``, ``loggers/groot2_protocol.h``,
protocol 2): a REP socket on the port (1667 by default) answers multipart requests whose first frame is a
6-byte header (protocol uint8, request type char, request id uint32, little-endian); each reply starts with
that header (protocol set to 2) and the server's 16-byte tree UUID, then the payload:

- ``T`` FULLTREE: the tree's XML with a ``_uid`` on every node (interop/groot2_tree.py);
- ``S`` STATUS: 3 bytes per node, uid (uint16) and status (0 idle, 1 running, 2 success, 3 failure;
  10 + the last status for a node that became idle after running);
- ``B`` BLACKBOARD: a MessagePack map (empty here: the mission's blackboard is not published);
- ``r``/``t``: recording of status transitions (6-byte µs timestamp, uid, status each);
- ``D``, ``A``, ``X``: hooks listed, removed, disabled (there are none).

Breakpoints (``I``, ``R``, ``U``: hooks that pause or replace a node) are refused with an error reply, as
is any other request: ``["error", reason]``. A PUB socket on the next port is bound as BehaviorTree.CPP
binds it; nothing is published on it.

The executor's thread only snapshots statuses after each tick (a list compare when nothing changed); a
background thread answers requests from the last snapshot, under a lock. pyzmq is imported here only:
``bt-run`` without ``--groot`` never loads it.
"""

from __future__ import annotations

import os
import struct
import threading
import time
from collections import deque
from typing import Any

from py_trees.common import Status

from bt_humanoid.errors import UserError
from bt_humanoid.interop.groot2_tree import Groot2Tree

DEFAULT_PORT = 1667
PROTOCOL = 2
HEADER = struct.Struct("<BBI")  # protocol, request type, request id
#: py_trees statuses as BehaviorTree.CPP's NodeStatus (IDLE 0, RUNNING 1, SUCCESS 2, FAILURE 3, SKIPPED 4)
CODES = {Status.INVALID: 0, Status.RUNNING: 1, Status.SUCCESS: 2, Status.FAILURE: 3}
IDLE_FROM = 10  # an idle node's status is 10 + the status it had before it was reset (BehaviorTree.CPP's)
MAX_TRANSITIONS = 1000  # transitions kept while recording, as BehaviorTree.CPP keeps them
EMPTY_MSGPACK_MAP = b"\x80"
INSTALL_HINT = "pip install 'bt-humanoid[groot]' (pyzmq)"
POLL_MS = 100


def import_zmq() -> Any:
    """pyzmq, or a UserError saying how to install it."""
    try:
        import zmq
    except ImportError:
        raise UserError("--groot needs pyzmq, which is not installed", hint=INSTALL_HINT) from None
    return zmq


class Groot2Server:
    """Serves ``tree`` on ``port`` (REP) and ``port + 1`` (PUB) until ``close()``; call ``snapshot()`` after
    every tick. Binding fails at once, as a UserError, when a port is taken."""

    def __init__(self, tree: Groot2Tree, port: int = DEFAULT_PORT, host: str = "*") -> None:
        zmq = import_zmq()
        if not 1 <= port <= 65534:
            raise UserError(f"--groot {port}: not a port", hint="valid: 1 to 65534 (it uses PORT and PORT + 1)")
        self.tree = tree
        self.port = port
        self._zmq = zmq
        self._uuid = os.urandom(16)  # Groot2 tells a new tree from the last one by it
        count = len(tree.nodes)
        self._last = [Status.INVALID] * count
        self._codes = bytearray(count)
        self._status = bytearray(3 * count)
        for index in range(count):
            struct.pack_into("<HB", self._status, 3 * index, index + 1, 0)
        self._lock = threading.Lock()
        self._recording_since: float | None = None
        self._transitions: deque[bytes] = deque(maxlen=MAX_TRANSITIONS)
        self.requests = 0
        self._context = zmq.Context()
        self._server = self._context.socket(zmq.REP)
        self._publisher = self._context.socket(zmq.PUB)
        for sock in (self._server, self._publisher):
            sock.setsockopt(zmq.LINGER, 0)
            sock.setsockopt(zmq.SNDTIMEO, 1000)
        try:
            self._server.bind(f"tcp://{host}:{port}")
            self._publisher.bind(f"tcp://{host}:{port + 1}")
        except zmq.ZMQError as error:
            self._context.destroy(linger=0)
            raise UserError(
                f"--groot {port}: cannot serve on ports {port} and {port + 1}: {error.strerror}",
                hint="give a free port: --groot PORT",
            ) from None
        self._running = threading.Event()
        self._running.set()
        self._thread = threading.Thread(target=self._serve, name="groot2-server", daemon=True)
        self._thread.start()

    # --- the executor's side ------------------------------------------------------------------

    def snapshot(self, *_: object) -> None:
        """Take the nodes' statuses now (after a tick): what STATUS requests answer until the next snapshot."""
        statuses = [node.status for node in self.tree.nodes]
        if statuses == self._last:
            return
        now = time.perf_counter()
        changed = []
        for index, (old, new) in enumerate(zip(self._last, statuses, strict=True)):
            if old is not new:
                code = CODES[new]
                self._codes[index] = IDLE_FROM + CODES[old] if code == 0 else code
                changed.append((index + 1, code))
        self._last = statuses
        with self._lock:
            self._status[2::3] = self._codes
            if self._recording_since is not None:
                stamp = round((now - self._recording_since) * 1e6)
                for uid, code in changed:
                    self._transitions.append(stamp.to_bytes(8, "little")[:6] + struct.pack("<HB", uid, code))

    def close(self) -> None:
        """Stop answering and free the ports."""
        self._running.clear()
        self._thread.join()
        self._context.destroy(linger=0)

    def __enter__(self) -> Groot2Server:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- the server thread ------------------------------------------------------------------------

    def _serve(self) -> None:
        zmq = self._zmq
        poller = zmq.Poller()
        poller.register(self._server, zmq.POLLIN)
        while self._running.is_set():
            if not poller.poll(POLL_MS):
                continue
            try:
                request = self._server.recv_multipart(zmq.NOBLOCK)
                self._server.send_multipart(self.reply(request))
            except zmq.ZMQError:
                continue  # a client gone between its request and our reply: the REP socket moves on
        self._server.close(linger=0)
        self._publisher.close(linger=0)

    def reply(self, request: list[bytes]) -> list[bytes]:
        """The reply frames to one request's frames."""
        self.requests += 1
        if not request or len(request[0]) != HEADER.size:
            return [b"error", b"wrong request header"]
        _, kind, request_id = HEADER.unpack(request[0])
        header = HEADER.pack(PROTOCOL, kind, request_id) + self._uuid
        kind = chr(kind)
        if kind == "T":
            return [header, self.tree.xml.encode()]
        if kind == "S":
            with self._lock:
                return [header, bytes(self._status)]
        if kind in "Br":
            if len(request) != 2:
                return [b"error", b"must be 2 parts message"]
            if kind == "B":
                return [header, EMPTY_MSGPACK_MAP]
            return [header, *self._toggle_recording(request[1])]
        if kind == "t":
            with self._lock:
                transitions = b"".join(self._transitions)
                self._transitions.clear()
            return [header, transitions]
        if kind == "D":
            return [header, b"[]"]
        if kind in "AX":
            return [header]
        if kind in "IRU":
            return [b"error", b"breakpoints (hooks) are not supported by bt-humanoid's monitor"]
        return [b"error", b"Request not recognized"]

    def _toggle_recording(self, command: bytes) -> list[bytes]:
        with self._lock:
            if command == b"start":
                self._recording_since = time.perf_counter()
                self._transitions.clear()
                return [str(round(time.time() * 1e6)).encode()]  # µs since the epoch: the client's zero
            if command == b"stop":
                self._recording_since = None
        return []
