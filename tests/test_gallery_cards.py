"""What a gallery card says of how a render was made (issue 24): the overrides it was rendered with, as
metadata.json records them ("overrides", as given on the command line), and for a comparison each variant
with when it parts from the finest and until when it is faithful. The renders are real and small, made by
the CLI; the cards are read back with an HTML parser, so what is checked is the text a browser shows."""
import html.parser
import json

import pytest

from conftest import out_folder, run_cli
from render.config.scene import load

# Two --set, one with quotes, brackets and a space: each must come back on the card exactly as given.
SETS = ["video.duration=1", 'video.formats=["mp4", "gif"]']
SMALL = ["video.width=256", "video.height=144", "video.fps=10"]
# rigid_chaos under f32 and f64: the f32 fan parts from the f64 one well before 9 s (tests/test_compare.py).
COMPARE = ["pendulums.count=10", "video.width=320", "video.height=180", "video.fps=10", "video.duration=9",
           'video.formats=["mp4"]']


class Card(html.parser.HTMLParser):
    """A card's <dt>/<dd> pairs as the text a browser shows, and the text of each <code> and <span> in a <dd>."""

    def __init__(self, markup: str):
        super().__init__()
        self.rows, self.parts, self._in, self._dt = {}, {}, None, None
        self.feed(markup)

    def handle_starttag(self, tag, attrs):
        if tag in ("dt", "dd", "code", "span"):
            self._in = tag if tag in ("dt", "dd") else self._in
            if tag in ("code", "span"):
                self.parts.setdefault(self._dt, []).append("")
            self._tag = tag

    def handle_endtag(self, tag):
        if tag in ("code", "span"):
            self._tag = self._in

    def handle_data(self, data):
        if self._in == "dt" and self._tag == "dt":
            self._dt = data
            self.rows[data] = ""
        elif self._in == "dd":
            self.rows[self._dt] += data
            if self._tag in ("code", "span"):
                self.parts[self._dt][-1] += data


def cards(page: str) -> dict[str, str]:
    """Each card's heading -> the card's HTML."""
    return {chunk.split("<h2>", 1)[1].split("</h2>", 1)[0]: chunk for chunk in page.split('<div class="card">')[1:]}


@pytest.fixture(scope="module")
def gallery(tmp_path_factory):
    out = tmp_path_factory.mktemp("cards") / "out"
    sets = [a for s in SETS + SMALL for a in ("--set", s)]
    r = run_cli("render", "classic", *sets, "--out", out, "--no-progress")
    assert r.returncode == 0, r.stderr
    vary = [a for s in COMPARE for a in ("--set", s)]
    r = run_cli("compare", "rigid_chaos", "--vary", "integrator.precision=f32,f64", *vary, "--out", out,
                "--no-progress")
    assert r.returncode == 0, r.stderr
    r = run_cli("render", "fractal_flip", *(a for s in ["video.duration=0.5", *SMALL] for a in ("--set", s)),
                "--out", out, "--no-progress")  # a map: metadata.json's energy is null
    assert r.returncode == 0, r.stderr
    r = run_cli("gallery", "--out", out)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("3 render(s) ->"), r.stdout  # none skipped
    metas = {"render": json.loads((out_folder(out, "classic") / "metadata.json").read_text()),
             "compare": json.loads((out_folder(out / "compare", "rigid_chaos") / "metadata.json").read_text()),
             "map": json.loads((out_folder(out, "fractal_flip") / "metadata.json").read_text())}
    page = cards((out / "index.html").read_text())
    return metas, {key: Card(page[meta["preset"]["name"]]) for key, meta in metas.items()}


def test_a_map_gets_a_card_and_its_energy_reads_not_measured(gallery):
    metas, found = gallery
    assert metas["map"]["energy"] is None and "map" in metas["map"]
    assert found["map"].rows["energy drift"] == "not measured", found["map"].rows


def test_metadata_records_the_overrides_as_given_and_the_card_shows_each(gallery):
    metas, found = gallery
    assert metas["render"]["overrides"] == SETS + SMALL  # in the order given, spelled as given
    assert found["render"].parts["overrides"] == SETS + SMALL  # one <code> each, unescaped by the parser as shown
    assert metas["compare"]["overrides"] == COMPARE  # --vary is not among them: it is compare.vary
    assert found["compare"].parts["overrides"] == COMPARE


def test_a_comparison_card_shows_when_each_variant_parts_and_until_when_it_is_faithful(gallery):
    metas, found = gallery
    meta, card = metas["compare"], found["compare"]
    variants, finest = meta["compare"]["variants"], meta["compare"]["finest"]
    assert [v["values"]["integrator.precision"] for v in variants] == ["f32", "f64"] and finest == 1
    assert variants[0]["divergence_s"] is not None  # the f32 fan parts: the card has a time to show
    assert "variants" not in found["render"].rows  # a plain render has no such row
    shown = card.parts["variants"]
    assert len(shown) == len(variants)
    for i, (v, line) in enumerate(zip(variants, shown)):
        until = v["faithfulness"]["faithful_until_s"]
        until = "the end" if until >= meta["duration"] else f"{until:.2f} s"
        parts = ("the one the others part from" if i == finest else
                 "never parts from the finest" if v["divergence_s"] is None else
                 f"parts from the finest at {v['divergence_s']:.2f} s")
        assert line == f"{v['label']}: {parts}, faithful until {until}", line


def test_the_preset_as_written_has_no_overrides_and_each_recorded_one_makes_the_same_scene():
    """quality first, then each --set, then the API's keyword values; replayed as --set they give the same scene."""
    assert load("classic").overrides == ()
    scene = load("classic", ["video.duration=1", 'video.formats=["mp4"]'], "draft",
                 {"pendulums.gravity": 9.5, "description": 'a "quoted" <b>'})
    assert scene.overrides == ("quality=draft", "video.duration=1", 'video.formats=["mp4"]',
                               "pendulums.gravity=9.5", 'description="a \\"quoted\\" <b>"')
    again = load("classic", list(scene.overrides))
    assert again == scene and again.hash() == scene.hash()
    assert again.overrides == scene.overrides  # all of them now --set, spelled the same
    assert scene.replace(name="x").overrides == scene.overrides  # output_name, --budget keep them
    assert "overrides" not in scene.to_dict()  # not part of the scene: its hash and folder are as before
    assert scene.hash() == load("classic", ["video.duration=1.0", 'video.formats=["mp4"]', "pendulums.gravity=9.5",
                                            'description="a \\"quoted\\" <b>"'], "draft").hash()
