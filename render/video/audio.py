"""The `audio` effect: a stereo track made from the fan's motion, left from θ1 and right from θ2.

Each heard pendulum (up to VOICES, evenly spaced over the fan, its ends included) sings one voice per channel,
a sine whose pitch follows its link's angle. While the fan swings together every voice has the same pitch
and the same phase, so they add up to one clear, gliding tone; as the pendulums part, the voices spread over
two octaves and their sum becomes a dense, noisy cluster: the spread is heard as the tone breaking up.

Pure numpy and no randomness: the same angles give the same samples (and the angles are the same at any
thread count). The track is exactly as long as the video, frames/fps seconds; render/video/mp4.py muxes it
into the MP4 as AAC.
"""
from __future__ import annotations

import numpy as np

from .mp4 import AUDIO_CODEC, AUDIO_KBPS, AUDIO_RATE
from ..physics import registry

VOICES = 64  # pendulums heard: a dense cluster once apart; synthesis costs grow with these, not with the fan
LOW_HZ, OCTAVES = 220.0, 2.0  # a hanging link sings A3, an upright one A5
LEVEL_S = 0.25  # the loudness is evened out over blocks this long (see level)
FADE_S = 0.02  # raised-cosine fades at both ends: no click where the track starts and stops
PEAK = 10 ** (-1 / 20)  # -1 dBFS: headroom for the AAC encoder's overshoot
CHUNK = 1 << 14  # samples levelled at once (level)
# Frames made at once (Track): their work arrays, VOICES x 2 x 1600 floats at 60 fps (0.8 MB), stay in the cache.
# rigid_chaos's own 64 voices over its 1200 frames (pipeline.record's angles), synthesise() in 6 rounds: 0.24-0.27 s
# in chunks of 2, 0.24-0.28 in chunks of 4, 0.27-0.28 in chunks of 8 (`python benchmarks/audio_track.py --chunks 2
# 4 8`, 2-core Xeon, AVX-512, 2026-12-07). The samples are the same to the bit at any chunk size: each is made by
# the same elementwise steps.
CHUNK_FRAMES = 2


def heard(scene) -> bool:
    """Whether a render carries a track: the effect is on and there is an MP4 to carry it. A comparison has
    none: its panels are separate fans, and one track could follow only one of them."""
    return scene.has("audio") and "mp4" in scene.video.formats and not scene.compare


def peak_bytes(scene) -> int:
    """What making the track holds at most (render/config/budget.py counts it): the float32 samples, 8 bytes a
    stereo sample, held from the first frame, and while level() evens out a channel its squares in float32 and
    again in float64, 12 bytes more (4 to spare for numpy's smaller temporaries); a chunk's work arrays, two float32
    ones of its samples for every voice; its pitches and phases. tracemalloc: 20.9 MB for rigid_chaos (a Track fed
    its 1200 frames of 64 voices, then finished: `python benchmarks/audio_track.py`), against 24.7 MB here."""
    voices = min(VOICES, scene.pendulums.count)
    per = -(-AUDIO_RATE // scene.video.fps)
    work = (CHUNK_FRAMES + 1) * voices * 8 * (registry.get(scene.system).D + 2 * 5)
    return work + 2 * CHUNK_FRAMES * voices * 2 * per * 4 + 24 * scene.frames * per


class Voices:
    """The heard pendulums' first two angles, read frame by frame as a render steps and made into the track as
    they come (Track); then the track."""

    def __init__(self, sim, fps: int, frames: int):
        self.sim = sim
        self.picks = np.unique(np.linspace(0, sim.n - 1, min(VOICES, sim.n)).round().astype(np.int64))
        self.q = np.empty((1, len(self.picks), sim.D))  # the heard pendulums' coordinates at this frame
        self.made = Track(frames, len(self.picks), fps)

    def record(self):
        """Call once per frame, with the simulation at that frame's time (frame 0 is t = 0)."""
        self.sim.read_out("rows_into", self.q, 0, self.picks)
        self.made.add(self.q[:, :, :2])

    def track(self) -> tuple[int, np.ndarray]:
        """(rate, int16 samples of shape (S, 2)): what Encoder.close muxes."""
        return self.made.finish()

    def summary(self) -> dict:
        """What metadata.json says of the track."""
        return {"codec": AUDIO_CODEC, "rate": AUDIO_RATE, "channels": 2, "bitrate_kbps": AUDIO_KBPS,
                "voices": len(self.picks), "left": "theta1", "right": "theta2",
                "pitch_hz": [LOW_HZ, LOW_HZ * 2 ** OCTAVES]}


def pitch(theta: np.ndarray) -> np.ndarray:
    """Hz of a voice at link angle θ: sin²(θ/2) is 0 hanging down and 1 upright and smooth through a flip,
    so a link that loops over the top glides up and down again, without a jump; and the angle is never
    wrapped, so one that has turned 2π more than its neighbour sings the same note."""
    return LOW_HZ * 2.0 ** (OCTAVES * np.sin(theta / 2) ** 2)


def synthesise(angles: np.ndarray, fps: int, rate: int = AUDIO_RATE) -> tuple[int, np.ndarray]:
    """(rate, int16 samples (S, 2)) from angles (frames, voices, 2): a Track fed every frame at once."""
    track = Track(len(angles), angles.shape[1], fps, rate)
    track.add(angles)
    return track.finish()


class Track:
    """The track of `frames` frames, made as their angles come (add()), so that after the last frame only its end
    and the levelling are left (finish()). In a render that is the part after the last frame, when nothing else
    of ours runs and the MP4's track waits for it: rigid_chaos's track takes 0.24-0.27 s made whole, and fed frame
    by frame leaves 0.018-0.022 s to finish() (`python benchmarks/audio_track.py`, 6 rounds, 2-core Xeon, AVX-512,
    2026-12-07).

    Frame f is shown from f/fps to (f+1)/fps and the pitch glides linearly from its value to the next frame's
    (the last holds): each voice's phase, the integral of its pitch, is then exact in closed form, with no voice
    ever jumping. So a frame is made once the next one's angles are in. Every frame gets the same whole number
    of samples, so the work is whole arrays (frames, voices, 2, samples) with no gathering: the rate is the next
    multiple of fps at or above `rate` (48000 itself at the fps that divide it: 60, 50, 30, 25, 24 ...), and
    ffmpeg resamples the others to `rate`. Float32 (half the memory) within a frame, where the phase grows by at
    most 2π·880/fps (92 rad at 60 fps: an error below 1e-5 rad); float64 for the phases at frame starts, which
    sum the whole track, frame after frame as a cumulative sum would.
    """

    def __init__(self, frames: int, voices: int, fps: int, rate: int = AUDIO_RATE):
        self.frames, self.per = frames, -(-rate // fps)
        self.rate, self.turn = self.per * fps, 2 * np.pi / fps  # radians per Hz over one frame
        self.x = np.empty((frames * self.per, 2), np.float32)  # level() sets the scale, not the number of voices
        self.w = np.arange(self.per, dtype=np.float32) / np.float32(self.per)  # a sample's place within its frame
        self.ww = self.w * self.w
        self.work = np.empty((2, CHUNK_FRAMES, voices, 2, self.per), np.float32)  # a chunk's phases and glides
        # the phase at the next frame's start, unwrapped; every voice starts at 0: a fan together starts in unison
        self.phase = np.zeros((voices, 2))
        self.hz = np.empty((0, voices, 2))  # the pitches of the frames added and not yet made
        self.made = 0  # frames made

    def add(self, angles: np.ndarray):
        """The angles (n, voices, 2) of the next n frames; makes every frame whose next one is in."""
        self.hz = np.concatenate([self.hz, pitch(angles)])
        while len(self.hz) > CHUNK_FRAMES:
            self._make(CHUNK_FRAMES, self.hz[1:CHUNK_FRAMES + 1])

    def finish(self) -> tuple[int, np.ndarray]:
        """(rate, int16 samples (S, 2)) once every frame's angles are in: the last frames, then the levelling."""
        if self.made == self.frames > 0:
            raise ValueError("the track is finished: its samples are levelled once")
        if self.made + len(self.hz) != self.frames:
            raise ValueError(f"the track has the angles of {self.made + len(self.hz)} frames, not {self.frames}")
        while len(self.hz):
            n = min(CHUNK_FRAMES, len(self.hz))
            self._make(n, np.concatenate([self.hz[1:n + 1], self.hz[-1:]])[:n])  # the last holds its pitch
        return self.rate, quantise(fade(level(self.x, self.rate), self.rate))

    def _make(self, n: int, after: np.ndarray):
        """The samples of the first n frames waiting, whose next frames' pitches are `after`."""
        hz, self.hz = self.hz[:n], self.hz[n:]
        glide = after - hz  # to the next frame's pitch
        start = np.empty_like(hz)
        for k in range(n):
            start[k] = self.phase % (2 * np.pi)
            self.phase = self.phase + (hz[k] + glide[k] / 2) * self.turn
        ph, quad = self.work[0, :n], self.work[1, :n]
        np.multiply((hz * self.turn).astype(np.float32)[..., None], self.w, out=ph)
        np.multiply((glide * self.turn / 2).astype(np.float32)[..., None], self.ww, out=quad)
        ph += quad
        ph += start[..., None].astype(np.float32)
        a = self.made * self.per
        self.x[a:a + n * self.per].reshape(n, self.per, 2)[:] = np.sin(ph, out=ph).sum(axis=1).transpose(0, 2, 1)
        self.made += n


def level(x: np.ndarray, rate: int) -> np.ndarray:
    """Even out each channel's loudness, in place. V voices in phase are √V times louder than V voices apart
    (18 dB for 64), so without this the fan would fall quiet as it parts and what is heard would be loudness,
    not the tone breaking up. Each channel is divided by its RMS over LEVEL_S blocks, the gain gliding
    linearly from block centre to block centre."""
    n = len(x)
    starts = np.arange(0, n, max(1, round(rate * LEVEL_S)))
    sizes = np.diff(np.append(starts, n))
    centres = starts + sizes / 2
    for c in range(x.shape[1]):
        col = x[:, c]
        rms = np.sqrt(np.add.reduceat(col * col, starts, dtype=np.float64) / sizes)
        gain = 1 / np.maximum(rms, max(1e-3 * rms.max(), 1e-12))  # near silence is not blown up into noise
        for a in range(0, n, CHUNK):  # in pieces: an hour's track is 173M samples
            col[a:a + CHUNK] *= np.interp(np.arange(a, min(a + CHUNK, n)), centres, gain)
    return x


def fade(x: np.ndarray, rate: int) -> np.ndarray:
    """Raised-cosine fades in and out, in place, each at most half the track (a one-frame video is all fade)."""
    n = min(round(rate * FADE_S), len(x) // 2)
    ramp = (np.sin(0.5 * np.pi * (np.arange(n) + 0.5) / n)[:, None] ** 2).astype(x.dtype)
    x[:n] *= ramp
    x[len(x) - n:] *= ramp[::-1]
    return x


def quantise(x: np.ndarray) -> np.ndarray:
    """16-bit samples, both channels scaled by one factor (the balance kept) to peak at PEAK: never clipped."""
    top = float(np.abs(x).max())
    x *= PEAK * 32767 / top if top > 0 else 0.0
    return np.rint(x, out=x).astype("<i2")
