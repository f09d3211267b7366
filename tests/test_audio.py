"""The `audio` effect (render/video/audio.py): a stereo AAC track in the MP4, made from the fan's angles.

Decoded back with ffmpeg: one AAC stereo stream as long as the video; a clear tone while the fan is together
and a broad spectrum once it has parted, with the parting read off the independent reference (scipy DOP853
on render/physics/reference.py's equations), not off the render; the same samples again at another thread count;
the video stream byte for byte the one a render without audio writes; bad input refused with one line."""
import hashlib
import re
import subprocess
from types import SimpleNamespace

import imageio_ffmpeg
import numpy as np
import pytest

from conftest import run_cli
from render.video import audio
from render.config import budget
from render.video import encode, mp4, pipeline
from render.physics import reference, registry
from render.errors import EncodeError, SceneError
from render.config.scene import load

FFMPEG = imageio_ffmpeg.get_ffmpeg_exe()  # the bundle has no ffprobe: ffmpeg -i describes the streams
# rigid_chaos, small: 24 pendulums 1e-3 rad apart over the fan part at about 3.5 s (the preset's 100
# pendulums 1e-4 apart take 4 to 8 s), within a 6 s video.
SMALL = ["video.width=256", "video.height=144", "video.fps=20", "video.duration=6", "pendulums.count=24",
         "pendulums.spread=1e-3", 'video.formats=["mp4"]']
WINDOW = 2048  # samples (43 ms): short enough that one voice's glide stays within a few bins


def decode(mp4) -> np.ndarray:
    """The MP4's audio as int16 (samples, 2), at its own rate."""
    raw = subprocess.run([FFMPEG, "-v", "error", "-i", str(mp4), "-map", "0:a", "-f", "s16le", "-"],
                         capture_output=True, check=True).stdout
    return np.frombuffer(raw, "<i2").reshape(-1, 2)


def streams(mp4) -> list[str]:
    log = subprocess.run([FFMPEG, "-hide_banner", "-i", str(mp4)], capture_output=True, text=True).stderr
    return [line.strip() for line in log.splitlines() if line.strip().startswith("Stream #")]


def h264(mp4) -> bytes:
    """The video stream's packets as an Annex B H.264 stream: the same bytes if the same video was muxed."""
    return subprocess.run([FFMPEG, "-v", "error", "-i", str(mp4), "-map", "0:v", "-c", "copy", "-bsf:v",
                           "h264_mp4toannexb", "-f", "h264", "-"], capture_output=True, check=True).stdout


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    scene = load("rigid_chaos", SMALL)
    out = tmp_path_factory.mktemp("audio")
    meta = pipeline.render(scene, out)
    return scene, meta, scene.out_dir(out) / f"{scene.name}.mp4"


def test_the_mp4_has_one_aac_stereo_stream_as_long_as_the_video(rendered):
    scene, meta, mp4 = rendered
    found = streams(mp4)
    sound = [s for s in found if "Audio:" in s]
    assert len(found) == 2 and len(sound) == 1, found
    assert re.search(r"Audio: aac \(LC\).*48000 Hz, stereo", sound[0]), sound[0]
    samples = len(decode(mp4))
    assert abs(samples - meta["frames"] / meta["fps"] * 48000) <= 1024, samples  # one AAC frame
    assert meta["audio"] == {"codec": "aac", "rate": 48000, "channels": 2, "bitrate_kbps": 128, "voices": 24,
                             "left": "theta1", "right": "theta2", "pitch_hz": [220.0, 880.0]}
    assert sorted(p.name for p in mp4.parent.iterdir()) == ["metadata.json", mp4.name]  # no sound file beside
    system = registry.get(scene.system)
    sizes = budget.output(scene, system, False)
    assert "audio" in sizes[2] and meta["outputs"][mp4.name] < sizes[0]
    assert "the audio track being made" in budget.memory(scene, system, False)[2]


def spectrum_shape(x: np.ndarray) -> tuple[float, float]:
    """Over short windows of one channel, the means of (the energy within ±3 bins of the peak over all of it,
    spectral flatness over the voices' range of 220-880 Hz): (~1, ~0) for one tone, lower and higher for a
    cluster. Measured: (0.9999, 3e-5) and (0.5, 0.27) before and after the fan parts."""
    peaks, flats = [], []
    lo, hi = (int(hz * WINDOW / 48000) for hz in (audio.LOW_HZ, audio.LOW_HZ * 2 ** audio.OCTAVES))
    for a in range(0, len(x) - WINDOW + 1, WINDOW):
        p = np.abs(np.fft.rfft(x[a:a + WINDOW] * np.hanning(WINDOW))) ** 2 + 1e-12
        k = p.argmax()
        peaks.append(p[max(0, k - 3):k + 4].sum() / p.sum())
        band = p[lo:hi]
        flats.append(np.exp(np.log(band).mean()) / band.mean())
    return float(np.mean(peaks)), float(np.mean(flats))


def test_one_tone_while_the_fan_is_together_a_broad_spectrum_once_it_has_parted(rendered):
    scene, meta, mp4 = rendered
    t = np.arange(meta["frames"]) / meta["fps"]
    theta, _ = reference.solve(scene, reference.initial_state(scene), t[-1], t_eval=t, rtol=1e-10, atol=1e-10)
    spread = theta.max(axis=1) - theta.min(axis=1)  # (frames, 2): over the fan, per link
    x = decode(mp4) / 32768.0
    for c, side in enumerate(("left: theta1", "right: theta2")):
        parting = t[np.argmax(spread[:, c] >= 0.01)]  # where the link's fan first spans 0.01 rad
        apart = t[np.argmax(spread[:, c] > 1.0)]
        assert 1.0 < parting < apart < 5.0 and (spread[t >= apart, c] > 0.3).all(), (side, parting, apart)
        before = spectrum_shape(x[int(0.1 * 48000):int(parting * 48000), c])  # after the fade in
        after = spectrum_shape(x[int(apart * 48000):int((t[-1] - 0.05) * 48000), c])  # before the fade out
        assert before[0] > 0.95 and before[1] < 0.01, (side, parting, before)
        assert after[0] < 0.75 and after[1] > 0.1, (side, apart, after)


def test_the_same_samples_again_at_another_thread_count(rendered, tmp_path):
    scene, meta, mp4 = rendered
    again = pipeline.render(scene, tmp_path, threads=1)
    other = scene.out_dir(tmp_path) / mp4.name
    assert np.array_equal(decode(mp4), decode(other))
    assert hashlib.sha256(mp4.read_bytes()).digest() == hashlib.sha256(other.read_bytes()).digest()
    assert again["audio"] == meta["audio"]


VIDEO = SimpleNamespace(width=64, height=48, fps=10, formats=("mp4",), gif_width=352, gif_fps=20)


def encode_frames(folder, track=None):
    """Ten frames of a moving gradient through the Encoder, with `track` muxed in if given."""
    folder.mkdir()
    enc = encode.Encoder(folder, "x", VIDEO, 10)
    ramp = np.add.outer(np.arange(48), np.arange(64)).astype(np.uint8)
    for f in range(10):
        enc.write(np.repeat((ramp * (f + 1))[..., None], 3, axis=2))
    return enc.close(track)


def test_the_track_leaves_the_video_stream_as_it_was_and_a_failed_mux_leaves_nothing(tmp_path, monkeypatch):
    angles = np.full((10, 3, 2), 1.0)
    track = audio.synthesise(angles, VIDEO.fps)
    encode_frames(tmp_path / "plain")
    sizes = encode_frames(tmp_path / "sound", track)
    assert list(sizes) == ["x.mp4"] and [p.name for p in (tmp_path / "sound").iterdir()] == ["x.mp4"]
    assert h264(tmp_path / "sound" / "x.mp4") == h264(tmp_path / "plain" / "x.mp4")
    assert len(streams(tmp_path / "plain" / "x.mp4")) == 1 and len(decode(tmp_path / "sound" / "x.mp4")) > 0
    monkeypatch.setattr(mp4, "AUDIO_CODEC", "no_such_codec")
    with pytest.raises(EncodeError, match="failed adding the audio"):
        encode_frames(tmp_path / "failed", track)
    assert not any((tmp_path / "failed").iterdir())  # neither the MP4 nor either temporary


def test_a_still_fan_sings_its_pitch_in_unison_and_fades_at_both_ends():
    still = np.full((30, 1, 2), np.pi / 2)  # sin²(π/4) = 1/2: an octave above 220 Hz
    rate, x = audio.synthesise(still, 30)
    assert rate == 48000 and x.shape == (48000, 2)
    spectrum = np.abs(np.fft.rfft(x[:, 0] * np.hanning(len(x))))
    assert abs(spectrum.argmax() * rate / len(x) - 440.0) <= 1.0
    assert np.abs(x).max() == round(audio.PEAK * 32767) and abs(x[0]).max() < 50 and abs(x[-1]).max() < 50
    swinging = np.cumsum(np.linspace(-0.05, 0.05, 60)).reshape(30, 1, 2) + 2.0
    one = audio.synthesise(swinging, 30)[1]
    unison = audio.synthesise(np.repeat(swinging, 8, axis=1), 30)[1]  # 8 voices together sound as one
    assert np.abs(unison.astype(int) - one).max() <= 1 and np.abs(one).max() > 20000  # float32 sums: 1 LSB
    rate, odd = audio.synthesise(swinging, 7)  # 7 fps does not divide 48000: a whole number of samples a frame
    assert rate == 7 * 6858 and len(odd) == 30 * 6858


def test_the_track_made_as_the_frames_come_is_the_track_made_at_once(monkeypatch):
    """A render feeds Track a frame at a time and makes frames in chunks as they come (render/video/audio.py): every
    grouping of frames and every chunk size gives the same samples to the bit as a whole-array reference written
    here from the same formulas (pitch, glide, phase at each frame start as a cumulative sum)."""
    rng = np.random.default_rng(3)
    angles = np.cumsum(rng.normal(0, 0.2, (61, 5, 2)), axis=0) + 2.0
    fps, per = 30, 1600
    hz = audio.pitch(angles)
    glide = np.diff(hz, axis=0, append=hz[-1:])
    turn = 2 * np.pi / fps
    start = np.zeros_like(hz)
    start[1:] = np.cumsum((hz + glide / 2)[:-1] * turn, axis=0) % (2 * np.pi)
    w = np.arange(per, dtype=np.float32) / np.float32(per)
    ph = (hz * turn).astype(np.float32)[..., None] * w
    ph += (glide * turn / 2).astype(np.float32)[..., None] * (w * w)
    ph += start[..., None].astype(np.float32)
    x = np.sin(ph).sum(axis=1).transpose(0, 2, 1).reshape(-1, 2)
    reference = audio.quantise(audio.fade(audio.level(x, fps * per), fps * per))
    for chunk in (1, 2, 7, 100):
        monkeypatch.setattr(audio, "CHUNK_FRAMES", chunk)
        track, f = audio.Track(len(angles), 5, fps), 0
        for n in (1, 3, 2, 10, 45):  # frames as they come, in groups of any size
            track.add(angles[f:f + n])
            f += n
        rate, samples = track.finish()
        assert rate == fps * per and np.array_equal(samples, reference), chunk
        with pytest.raises(ValueError, match="finished"):
            track.finish()
        assert np.array_equal(audio.synthesise(angles, fps)[1], reference)
    with pytest.raises(ValueError, match="the angles of 60 frames, not 61"):
        short = audio.Track(len(angles), 5, fps)
        short.add(angles[:60])
        short.finish()


def test_audio_is_refused_where_there_are_no_fan_angles(tmp_path):
    res = run_cli("render", "elastic_fan", "--out", tmp_path / "o", "--set",
                  'effects=["springs", "bobs", "audio"]')
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1, res.stderr
    assert "elastic_fan.toml: effects: 'audio'" in res.stderr and "not angles" in res.stderr
    assert not (tmp_path / "o").exists()
    with pytest.raises(SceneError, match="effects: 'audio' .* 'fractal'"):
        load("fractal", ['effects=["fractal", "audio"]'])
