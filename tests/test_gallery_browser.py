"""The gallery page in a real browser: headless Chromium loads `pendulum gallery`'s index.html from disk, every
video and image on it loads, a broken video is marked broken, and a screenshot is saved.

Skipped unless Chromium is installed (Debian: `apt-get install -y chromium`). The page's own script marks
each <video> and <img> with data-state="loaded" or "error" as the browser settles it; `--dump-dom` prints the
DOM after the page has loaded and its virtual time has run, so the marks are read without any driver. The
screenshot goes to out/gallery-browser/screenshot.png (look at it after a change to the page).
"""
import html.parser
import shutil
import struct
import subprocess
from pathlib import Path

import pytest

import render
from conftest import ROOT, run_cli

BROWSER = next((shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b)), None)
pytestmark = pytest.mark.skipif(BROWSER is None, reason="needs Chromium (Debian: apt-get install -y chromium)")

SMALL = {"video.duration": 1, "video.fps": 20, "video.width": 320, "video.height": 180}
SHOT = ROOT / "out" / "gallery-browser" / "screenshot.png"


def chromium(page: Path, tmp: Path, *args: str) -> str:
    """Run headless Chromium on a file; its stdout. 10 s of virtual time: the page's media settle in far less,
    and virtual time only runs while the page is idle, so this is no wall-clock wait."""
    cmd = [BROWSER, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--mute-audio",
           f"--user-data-dir={tmp / 'profile'}", "--virtual-time-budget=10000", "--window-size=1280,2000", *args,
           page.as_uri()]  # a tall window: every card in view, so lazy GIFs load too
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout


class Marks(html.parser.HTMLParser):
    """(tag, src, data-state) of every <video> and <img>, and the broken-file notes the script added."""

    def __init__(self):
        super().__init__()
        self.media, self.notes = [], 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag in ("video", "img"):
            self.media.append((tag, a.get("src"), a.get("data-state")))
        if tag == "div" and a.get("class") == "broken":
            self.notes += 1


def marks(dom: str) -> Marks:
    m = Marks()
    m.feed(dom)
    return m


@pytest.fixture(scope="module")
def gallery(tmp_path_factory):
    """An output root with an MP4+GIF render and a GIF-only one, and its page from `pendulum gallery`."""
    out = tmp_path_factory.mktemp("gallery") / "out"
    render.render(render.load("classic", **SMALL), out=out)
    render.render(render.load("classic", **SMALL, name="classic_gif", video={"formats": ["gif"]}), out=out)
    r = run_cli("gallery", "--out", out)
    assert r.returncode == 0 and r.stdout.strip() == f"2 render(s) -> {out / 'index.html'}", r.stderr
    return out


def test_every_video_and_image_on_the_gallery_loads_in_chromium(gallery, tmp_path):
    m = marks(chromium(gallery / "index.html", tmp_path, "--dump-dom"))
    assert ("video", "classic/classic.mp4", "loaded") in m.media
    assert ("img", "classic_gif/classic_gif.gif", "loaded") in m.media
    assert len(m.media) == 2 and all(state == "loaded" for _, _, state in m.media), m.media
    assert m.notes == 0
    page = (gallery / "index.html").read_text()
    assert 'poster="classic/classic.poster.jpg"' in page and (gallery / "classic/classic.poster.jpg").is_file()
    assert "until the end (median the end) at 0.001 rad" in page  # the certificate
    assert "MP4</a> (" in page and "GIF</a> (" in page  # the sizes


def test_a_broken_video_is_marked_on_its_card(gallery, tmp_path):
    out = tmp_path / "out"
    shutil.copytree(gallery / "classic", out / "classic")
    mp4 = out / "classic" / "classic.mp4"
    (out / "classic" / "classic.poster.jpg").unlink()
    mp4.write_bytes(mp4.read_bytes()[:200])  # the header of a file cut short
    assert run_cli("gallery", "--out", out).returncode == 0
    m = marks(chromium(out / "index.html", tmp_path, "--dump-dom"))
    assert m.media == [("video", "classic/classic.mp4", "error")] and m.notes == 1


def test_the_gallery_screenshot(gallery, tmp_path):
    SHOT.parent.mkdir(parents=True, exist_ok=True)
    SHOT.unlink(missing_ok=True)
    chromium(gallery / "index.html", tmp_path, "--hide-scrollbars", "--window-size=1280,900",  # the last wins
             f"--screenshot={SHOT}")
    data = SHOT.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and struct.unpack(">II", data[16:24]) == (1280, 900)
