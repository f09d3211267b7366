"""Where presets are found: $PENDULUM_PRESETS, then ./presets/, then the shipped ones; first match wins."""
import pytest

from render.config import catalog
from render.errors import SceneError
from render.config.scene import load

MINE = 'description = "{what}"\nsystem = "{system}"\n[pendulums]\ncount = 2\n'


@pytest.fixture
def elsewhere(tmp_path, monkeypatch):
    """A working folder outside the repository, with no $PENDULUM_PRESETS."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv(catalog.ENV, raising=False)
    return tmp_path


def write(folder, name, what):
    system = load("classic").system
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{name}.toml").write_text(MINE.format(what=what, system=system))


def test_the_shipped_presets_are_found_from_anywhere(elsewhere):
    shipped = sorted(p.stem for p in catalog.PRESET_DIR.glob("*.toml"))
    assert "classic" in shipped and [p.stem for p in catalog.list_presets()] == shipped
    assert catalog.preset_path("classic") == catalog.PRESET_DIR / "classic.toml"


def test_user_presets_come_first_and_are_listed(elsewhere, monkeypatch):
    env_a, env_b = elsewhere / "a", elsewhere / "b"
    write(elsewhere / "presets", "classic", "mine in ./presets")  # stands in for the shipped one
    write(elsewhere / "presets", "local_only", "only here")
    write(env_a, "classic", "mine in $PENDULUM_PRESETS")  # before ./presets
    write(env_b, "from_env", "second folder of the variable")
    monkeypatch.setenv(catalog.ENV, f"{env_a}:{env_b}")
    assert load("classic").description == "mine in $PENDULUM_PRESETS"
    assert load("local_only").description == "only here" and load("from_env").pendulums.count == 2
    listed = {p.stem: p for p in catalog.list_presets()}
    assert {"classic", "local_only", "from_env", "rigid_chaos"} <= set(listed)
    assert listed["classic"] == env_a / "classic.toml"  # one entry per name: the one that is used
    monkeypatch.delenv(catalog.ENV)
    assert load("classic").description == "mine in ./presets"


def test_a_missing_preset_names_the_close_ones_on_the_whole_path(elsewhere, monkeypatch):
    write(elsewhere / "mine", "my_fan", "x")
    monkeypatch.setenv(catalog.ENV, str(elsewhere / "mine"))
    with pytest.raises(SceneError, match="my_fn: no such preset .*did you mean 'my_fan'"):
        load("my_fn")
