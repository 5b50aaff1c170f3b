"""The rig board recording beside a run: `BoardInstrument`, an `Instrument`
(`rig.devices.protocols`), the real counterpart of the simulated board (`rig.sim.board`).

`connect(clock)` opens the board at its URL on the run's clock (every event's rig time is that
clock's: the board's clock is synchronised to it), writes each event into the recording folder as
it arrives (`BoardRecorder`), sets up the encoder and the photodiode and starts their streams;
`poll` raises the link's failure, if any (a port that could not be reopened, a folder that could not
be written); `finish` stops the streams, synchronises the clocks once more and writes
recording.json; `close` closes the link and the files, so an interrupted run keeps every event
received (without recording.json). `rig measure --board PORT` records one beside a live run,
`rig board record` one on its own.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import Any, Callable

from rig.board.link import SerialPort, open_serial_url
from rig.board.microcontroller import Microcontroller
from rig.board.recorder import BoardRecorder
from rig.clock import Clock
from rig.errors import RigError
from rig.fresh_outputs import removed_unless_recorded
from rig.board.settings import BoardSettings

class BoardInstrument:
    """The board at `url` recording into `out_dir`; see the module docstring. `options` go into
    recording.json beside the settings; `open_port` opens the URL (tests pass their own)."""

    def __init__(
        self, url: str, out_dir: Path, settings: BoardSettings = BoardSettings(), *, options: dict[str, Any] | None = None,
        open_port: Callable[[str], SerialPort] = open_serial_url,
    ) -> None:  # fmt: skip
        self.url = url
        self.out_dir = Path(out_dir)
        self.settings = settings
        self._options = options or {}
        self._open_port = open_port
        self._started = 0.0
        self._clock: Clock | None = None
        self.board: Microcontroller | None = None
        self.recorder: BoardRecorder | None = None

    def connect(self, clock: Clock) -> None:
        """Open the recording and the board; a board that does not answer leaves no recording behind."""
        with removed_unless_recorded(self.out_dir):
            self.recorder = BoardRecorder(self.out_dir)
            self._clock = clock
            s = self.settings
            self.board = Microcontroller(self.url, open_port=self._open_port, clock=clock.now, resync_every_s=s.resync_every_s)
            self.board.add_listener(self.recorder)
            try:
                self.board.connect()
                self.board.configure_encoder(s.encoder_rate_hz)
                self.board.configure_photodiode(s.rise, s.fall, s.raw_every)
                self.board.stream(encoder=True, photodiode=True, samples=s.raw_every > 0)
                self._started = clock.now()
            except BaseException:
                self.close()
                raise

    def poll(self) -> None:
        self._connected().check()

    def finish(self) -> None:
        board, recorder = self._connected(), self.recorder
        board.stream()
        board.sync()
        drift = board.clock_model.drift()
        recorder.write_metadata({
            "identity": asdict(board.identity),
            "options": {"duration_s": self._clock.now() - self._started, **asdict(self.settings), **self._options},
            "events": recorder.counts,
            "link": board.counters,
            "board_status": asdict(board.status()),
            "drift": asdict(drift) if drift else None,
        })  # fmt: skip

    def close(self) -> None:
        if self.board is not None:
            self.board.close()
        if self.recorder is not None:
            self.recorder.close()

    def _connected(self) -> Microcontroller:
        if self.board is None:
            raise RigError(f"the board at {self.url} is not connected")
        return self.board
