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
CHUNK = 1 << 14  # samples made at once: the work arrays stay at VOICES x 2 x CHUNK floats (8 MB)


def heard(scene) -> bool:
    """Whether a render carries a track: the effect is on and there is an MP4 to carry it. A comparison has
    none: its panels are separate fans, and one track could follow only one of them."""
    return scene.has("audio") and "mp4" in scene.video.formats and not scene.compare


def peak_bytes(scene) -> int:
    """What making the track holds at most (render/config/budget.py counts it): the heard pendulums' coordinates
    at every frame (float64), their first two angles turned into pitches and phases (about 5 float64 copies
    more), the work arrays of a chunk, and 16 bytes a stereo sample (float32 samples, a channel's squares, then
    int16). tracemalloc: 32 MB for rigid_chaos."""
    voices = min(VOICES, scene.pendulums.count)
    samples = scene.frames * -(-AUDIO_RATE // scene.video.fps)
    record = scene.frames * voices * 8 * (registry.get(scene.system).D + 2 * 5)
    return record + 2 * voices * 2 * CHUNK * 4 + 16 * samples


class Voices:
    """The heard pendulums' first two angles, recorded frame by frame as a render steps; then the track."""

    def __init__(self, sim, fps: int, frames: int):
        self.sim, self.fps = sim, fps
        self.picks = np.unique(np.linspace(0, sim.n - 1, min(VOICES, sim.n)).round().astype(np.int64))
        self.q = np.empty((frames, len(self.picks), sim.D))  # the heard pendulums' coordinates, frame by frame
        self.recorded = 0

    def record(self):
        """Call once per frame, with the simulation at that frame's time (frame 0 is t = 0)."""
        self.sim.read_out("rows_into", self.q, self.recorded, self.picks)
        self.recorded += 1

    def track(self) -> tuple[int, np.ndarray]:
        """(rate, int16 samples of shape (S, 2)): what Encoder.close muxes."""
        return synthesise(self.q[:self.recorded, :, :2], self.fps)

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
    """(rate, int16 samples (S, 2)) from angles (frames, voices, 2). Frame f is shown from f/fps to (f+1)/fps
    and the pitch glides linearly from its value to the next frame's (the last holds): each voice's phase,
    the integral of its pitch, is then exact in closed form, with no voice ever jumping.

    Every frame gets the same whole number of samples, so the work is whole arrays (frames, voices, 2,
    samples) with no gathering: the rate is the next multiple of fps at or above `rate` (48000 itself at
    the fps that divide it: 60, 50, 30, 25, 24 ...), and ffmpeg resamples the others to `rate`. Float32
    (half the memory) within a frame, where the phase grows by at most 2π·880/fps (92 rad at 60 fps: an
    error below 1e-5 rad); float64 for the phases at frame starts, which sum the whole track."""
    frames, voices = angles.shape[:2]
    per = -(-rate // fps)
    hz = pitch(angles)
    glide = np.diff(hz, axis=0, append=hz[-1:])  # to the next frame's pitch
    turn = 2 * np.pi / fps  # radians per Hz over one frame
    start = np.zeros_like(hz)  # every voice starts at phase 0: a fan together starts in unison
    start[1:] = np.cumsum((hz + glide / 2)[:-1] * turn, axis=0) % (2 * np.pi)
    w = np.arange(per, dtype=np.float32) / np.float32(per)  # a sample's place within its frame
    lin, quad = (hz * turn).astype(np.float32), (glide * turn / 2).astype(np.float32)
    x = np.empty((frames * per, 2), np.float32)  # level() sets the scale, not the number of voices
    chunk = max(1, CHUNK // per)  # frames
    for a in range(0, frames, chunk):
        b = slice(a, a + chunk)
        ph = lin[b, ..., None] * w
        ph += quad[b, ..., None] * (w * w)
        ph += start[b, ..., None].astype(np.float32)
        x.reshape(frames, per, 2)[b] = np.sin(ph, out=ph).sum(axis=1).transpose(0, 2, 1)
    return per * fps, quantise(fade(level(x, per * fps), per * fps))


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
