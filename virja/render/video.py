"""Video files: frames piped to ffmpeg (H.264), sound rendered by fluidsynth (AAC).

ffmpeg comes from imageio-ffmpeg (a static build on PyPI, so no system
package is needed); fluidsynth and a General MIDI soundfont are Debian
packages (``fluidsynth``, ``fluid-soundfont-gm``).  Where either is missing the
video is made silent and the caller is told why.
"""

from __future__ import annotations

import contextlib
import logging
import os
import shutil
import subprocess
import tempfile
import threading
from collections.abc import Iterable
from pathlib import Path
from queue import Queue

import mido
import numpy as np
from numpy.typing import NDArray

from virja import midispec
from virja.errors import ConfigError, NotAvailableError
from virja.events import Event, NoteOn

log = logging.getLogger(__name__)

SOUNDFONT_PATHS = (
    "/usr/share/sounds/sf2/FluidR3_GM.sf2",
    "/usr/share/sounds/sf2/default-GM.sf2",
    "/usr/share/soundfonts/FluidR3_GM.sf2",
    "/usr/share/soundfonts/default.sf2",
)


def ffmpeg_exe() -> str:
    try:
        import imageio_ffmpeg

        return str(imageio_ffmpeg.get_ffmpeg_exe())
    except Exception as exc:  # imageio-ffmpeg raises RuntimeError when no binary fits
        found = shutil.which("ffmpeg")
        if found:
            return found
        raise NotAvailableError(f"no ffmpeg for video output ({exc})") from exc


def check_soundfont(path: Path, where: str) -> Path:
    """``path`` if it is a readable SoundFont 2 file (RIFF ... sfbk), else a one-line
    ConfigError saying what it is instead."""
    try:
        with path.open("rb") as fh:
            head = fh.read(12)
    except OSError as exc:
        raise ConfigError(
            f"{where} {path}: cannot read it: {exc.strerror or exc}; give a .sf2 SoundFont"
        ) from None
    if head[:4] != b"RIFF" or head[8:12] != b"sfbk":
        raise ConfigError(f"{where} {path}: not a SoundFont 2 file (no RIFF sfbk header)")
    return path


def find_soundfont(explicit: str | None = None) -> Path | None:
    """The GM soundfont to use: ``explicit``, $VIRJA_SOUNDFONT, or a Debian path.

    An explicit soundfont that is not one is an error; a $VIRJA_SOUNDFONT that is
    not one is said in a warning, and the next candidate is used."""
    if explicit:
        return check_soundfont(Path(explicit), "--soundfont")
    env = os.environ.get("VIRJA_SOUNDFONT")
    if env:
        try:
            return check_soundfont(Path(env), "VIRJA_SOUNDFONT")
        except ConfigError as exc:
            log.warning("%s; using the default soundfont instead", exc)
    for cand in SOUNDFONT_PATHS:
        if Path(cand).is_file():
            return Path(cand)
    return None


def events_to_midi(events: Iterable[Event], path: Path, t0_s: float = 0.0) -> None:
    """Write note, controller and program events as a type 0 MIDI file starting at ``t0_s``."""
    tpb, tempo = 960, 500_000  # 1 tick = 1/1920 s at 120 bpm
    msgs: list[tuple[int, int, mido.Message]] = []
    for i, ev in enumerate(events):
        tick = max(0, round((ev.time_s - t0_s) * 1e6 / tempo * tpb))
        m = midispec.to_mido(ev)
        if m is None:
            continue
        msgs.append((tick, i, m))
    msgs.sort(key=lambda x: (x[0], x[1]))
    track = mido.MidiTrack()
    track.append(mido.MetaMessage("set_tempo", tempo=tempo, time=0))
    now = 0
    for tick, _, m in msgs:
        track.append(m.copy(time=tick - now))
        now = tick
    mf = mido.MidiFile(type=0, ticks_per_beat=tpb)
    mf.tracks.append(track)
    mf.save(str(path))


def render_audio(
    midi_path: Path, wav_path: Path, soundfont: Path, sample_rate: int = 44100
) -> None:
    """MIDI -> WAV with fluidsynth (fast, offline, no audio device)."""
    exe = shutil.which("fluidsynth")
    if exe is None:
        raise NotAvailableError("fluidsynth is not installed (apt-get install fluidsynth)")
    cmd = [
        exe,
        "-ni",
        "-q",
        "-g",
        "0.8",
        "-r",
        str(sample_rate),
        "-F",
        str(wav_path),
        str(soundfont),
        str(midi_path),
    ]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600, check=False)
    if proc.returncode != 0 or not wav_path.exists():
        raise NotAvailableError(
            f"fluidsynth failed ({proc.returncode}): {proc.stderr.strip()[:300]}"
        )


class VideoWriter:
    """Pipes RGB frames to ffmpeg; adds an audio track at ``audio_offset_s`` if given.

    With ``queue_frames`` > 0 the pipe is fed from a writer thread holding up to
    that many frames, so the caller (the GL loop) never waits on ffmpeg while it
    has room: drawing, read-back and encoding overlap.  Frames keep their order;
    a failed write is raised from the next :meth:`write_raw` or from :meth:`close`.
    """

    def __init__(
        self,
        path: Path,
        size: tuple[int, int],
        fps: float,
        audio: Path | None = None,
        audio_offset_s: float = 0.0,
        crf: int = 20,
        preset: str = "superfast",
        bottom_up: bool = False,
        queue_frames: int = 0,
    ) -> None:
        w, h = size
        if w % 2 or h % 2:
            raise ValueError(f"H.264 needs an even frame size, got {w}x{h}")
        self.path = path
        self.size = size
        cmd = [
            ffmpeg_exe(), "-y", "-loglevel", "error",
            "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{w}x{h}", "-r", f"{fps}", "-i", "-",
        ]  # fmt: skip
        if audio is not None:
            cmd += ["-i", str(audio)]
        if bottom_up:  # frames as GL reads them: let the encoder flip them
            cmd += ["-vf", "vflip"]
        cmd += ["-c:v", "libx264", "-preset", preset, "-crf", str(crf), "-pix_fmt", "yuv420p"]
        cmd += ["-threads", "2", "-movflags", "+faststart"]
        if audio is not None:
            # The offset is baked into the samples (silence padded, or the head cut),
            # not left to a container start time that some players and decoders
            # ignore; -shortest: the synth's reverb tail stops at the last frame.
            if audio_offset_s >= 0:
                shift = f"adelay=delays={audio_offset_s * 1000:.3f}:all=1"
            else:
                shift = f"atrim=start={-audio_offset_s:.6f},asetpts=PTS-STARTPTS"
            cmd += ["-af", shift, "-c:a", "aac", "-b:a", "160k"]
            cmd += ["-map", "0:v:0", "-map", "1:a:0", "-shortest"]
        cmd += [str(path)]
        self._proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stderr=subprocess.PIPE)
        self._err_text: str | None = None
        self.frames = 0
        self._queue: Queue[bytes | None] | None = None
        self._thread: threading.Thread | None = None
        self._failed: BaseException | None = None
        if queue_frames > 0:
            self._queue = Queue(maxsize=queue_frames)
            self._thread = threading.Thread(target=self._feed, name="virja-ffmpeg", daemon=True)
            self._thread.start()

    def _feed(self) -> None:
        """The writer thread: frames from the queue into ffmpeg's pipe, until None."""
        assert self._queue is not None and self._proc.stdin is not None
        while (data := self._queue.get()) is not None:
            if self._failed is not None:
                continue  # drain, so the producer never blocks on a dead pipe
            try:
                self._proc.stdin.write(data)
            except (BrokenPipeError, OSError) as exc:
                self._failed = exc

    def _raise_failed(self) -> None:
        if self._failed is not None:
            raise NotAvailableError(f"ffmpeg stopped: {self._stderr()}") from self._failed

    def _stop_thread(self) -> None:
        if self._thread is not None and self._queue is not None:
            self._queue.put(None)
            self._thread.join()
            self._thread = None

    def write_raw(self, data: bytes) -> None:
        """One frame of packed RGB bytes, in the row order the writer was opened with."""
        assert self._proc.stdin is not None
        if len(data) != self.size[0] * self.size[1] * 3:
            raise ValueError(
                f"frame of {len(data)} bytes, expected {self.size[0] * self.size[1] * 3}"
            )
        if self._queue is not None:
            self._raise_failed()
            self._queue.put(data)
            self.frames += 1
            return
        try:
            self._proc.stdin.write(data)
        except BrokenPipeError as exc:
            raise NotAvailableError(f"ffmpeg stopped: {self._stderr()}") from exc
        self.frames += 1

    def write(self, rgb: NDArray[np.uint8]) -> None:
        assert self._proc.stdin is not None
        if rgb.shape != (self.size[1], self.size[0], 3):
            raise ValueError(
                f"frame of shape {rgb.shape}, expected {(self.size[1], self.size[0], 3)}"
            )
        self.write_raw(np.ascontiguousarray(rgb).tobytes())

    def _stderr(self) -> str:
        """What ffmpeg said (read once, kept: a failed write and the close both report it)."""
        if self._err_text is None:
            assert self._proc.stderr is not None
            text = self._proc.stderr.read().decode(errors="replace").strip()
            # the last lines say why; keep them whole on one line
            self._err_text = " / ".join(text.splitlines()[-3:])[:500]
        return self._err_text

    def abort(self) -> None:
        """Stop ffmpeg and remove the unfinished file (an interrupted render)."""
        self._proc.kill()
        self._proc.wait()
        self._stop_thread()  # its writes fail on the dead pipe; it drains and ends
        for stream in (self._proc.stdin, self._proc.stderr):
            if stream is not None:
                with contextlib.suppress(OSError):
                    stream.close()
        self.path.unlink(missing_ok=True)

    def close(self) -> None:
        assert self._proc.stdin is not None
        self._stop_thread()  # every queued frame written first
        # ffmpeg may already have stopped; its exit status and message say why
        with contextlib.suppress(BrokenPipeError):
            self._proc.stdin.close()
        rc = self._proc.wait()
        if rc != 0:
            raise NotAvailableError(f"ffmpeg failed ({rc}): {self._stderr()}")
        self._raise_failed()  # a frame the writer thread could not hand over


def make_audio_track(
    events: list[Event], t0_s: float, workdir: Path, soundfont: str | None = None
) -> tuple[Path | None, str | None]:
    """Render ``events`` to a WAV in ``workdir``; returns (wav, None) or (None, why not)."""
    sf = find_soundfont(soundfont)
    if sf is None:
        return (
            None,
            "no General MIDI soundfont found (apt-get install fluid-soundfont-gm, or set VIRJA_SOUNDFONT); the video is silent",
        )
    if not any(isinstance(e, NoteOn) for e in events):
        return None, "no notes to sound; the video is silent"
    mid = workdir / "audio.mid"
    wav = workdir / "audio.wav"
    events_to_midi(events, mid, t0_s=t0_s)
    try:
        render_audio(mid, wav, sf)
    except NotAvailableError as exc:
        return None, f"{exc}; the video is silent"
    return wav, None


def temp_workdir() -> tempfile.TemporaryDirectory[str]:
    return tempfile.TemporaryDirectory(prefix="virja-")
