"""Commands to the board and their answers: each command goes out with a sequence number, and a
message whose reply_to is that number answers it; a command left unanswered is sent again."""

from __future__ import annotations

import itertools
import threading
from dataclasses import dataclass, field
from typing import Any, Callable

from rig.board.framing import encode_frame
from rig.board.link import READ_TIMEOUT_S, LinkDown, SerialLink
from rig.board.protocol import ProtocolSpec, protocol
from rig.errors import RigError


@dataclass(frozen=True)
class Answer:
    """The answers to one command, by message type, and when the command was sent and each answer
    arrived (rig clock)."""

    spec: ProtocolSpec
    sent: float
    answers: dict[int, dict[str, Any]]
    received: dict[int, float]

    def answer(self, name: str) -> dict[str, Any]:
        return self.answers[self.spec.type_id(name)]

    def received_at(self, name: str) -> float:
        return self.received[self.spec.type_id(name)]


@dataclass
class _Pending:
    """A command waiting for its answers: every message type in `expects`, or an ACK."""

    expects: tuple[int, ...]
    done: threading.Event = field(default_factory=threading.Event)
    answers: dict[int, dict[str, Any]] = field(default_factory=dict)
    received: dict[int, float] = field(default_factory=dict)
    ack_status: int | None = None
    link_lost: bool = False


class Requests:
    """The commands in flight on a link, on the link's clock; a command waits the link's
    reconnect_timeout_s for a dropped link to come back, and fails at once once its `stop` is set.

    reply_timeout_s: how long to wait for the answers to each try.
    check: raises the error that stopped the connection, if any.
    """

    def __init__(self, link: SerialLink, *, reply_timeout_s: float, check: Callable[[], None]) -> None:
        self._link = link
        self._reply_timeout = reply_timeout_s
        self._check = check
        self._seq = itertools.count(1)
        self._pending: dict[int, _Pending] = {}
        self._lock = threading.Lock()

    def send(self, command: str, *, expects: tuple[str, ...], fields: dict[str, int] | None, tries: int) -> Answer:
        """Sends a command and waits for all its answers (or an ACK refusing it), trying `tries` times."""
        spec = protocol()
        command_type = spec.type_id(command)
        payload = spec.layout(command_type).pack(**(fields or {}))
        for _ in range(tries):
            self._wait_for_link()
            seq = next(self._seq) % 256
            pending = _Pending(expects=tuple(spec.type_id(name) for name in expects))
            with self._lock:
                self._pending[seq] = pending
            try:
                sent = self._link.write(encode_frame(command_type, seq, payload, spec))
                if not pending.done.wait(self._reply_timeout) or pending.link_lost:
                    continue
            except LinkDown:
                continue
            finally:
                with self._lock:
                    self._pending.pop(seq, None)
            if pending.ack_status is not None and pending.ack_status != spec["RIG_STATUS_OK"]:
                raise RigError(f"the board refused {command}: {spec.status_name(pending.ack_status)}")
            return Answer(spec, sent, pending.answers, pending.received)
        self._check()
        raise RigError(
            f"the board at {self._link.url} did not answer {command} ({tries} tries, {self._reply_timeout} s each): "
            "check the port, the cable and that the board runs the rig firmware"
        )

    def _wait_for_link(self) -> None:
        """Returns once the port is open; raises if the link failed, closed or stayed down."""
        link = self._link
        deadline = link.clock() + link.reconnect_timeout_s
        while not link.up.wait(READ_TIMEOUT_S):
            self._check()
            if link.stop.is_set():
                raise RigError(f"the connection to the board at {link.url} is closed")
            if link.clock() > deadline:
                raise RigError(f"the link to the board at {link.url} stayed down for {link.reconnect_timeout_s} s")
        self._check()
        if link.stop.is_set():
            raise RigError(f"the connection to the board at {self._link.url} is closed")

    def resolve(self, reply_to: int, message_type: int, fields: dict[str, Any], received: float) -> None:
        """Hands an answer (a message with a reply_to) to the command it answers, if still waiting."""
        with self._lock:
            pending = self._pending.get(reply_to)
            if pending is None or pending.done.is_set():
                return
            if message_type == protocol()["RIG_MSG_ACK"]:
                pending.ack_status = fields["status"]
            elif message_type not in pending.expects:
                return
            pending.answers[message_type] = fields
            pending.received[message_type] = received
            if pending.ack_status is not None or all(kind in pending.answers for kind in pending.expects):
                pending.done.set()

    def fail_all(self) -> None:
        """The link went down or is closing: every command waiting stops waiting and tries again
        (which, after close(), fails at once)."""
        with self._lock:
            for pending in self._pending.values():
                pending.link_lost = True
                pending.done.set()
