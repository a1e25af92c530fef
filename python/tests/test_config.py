"""load_config from a file or a dict: the same keys and the same messages as the CLI; the
version and licence agree with the program's."""

from __future__ import annotations

import importlib.metadata
import pickle

import pytest

import softsight
from conftest import cli_error, run_cli

BAD_KEY = """\
markers:
  - name: red
    hsv: {h: [170, 10], s: [80, 255], v: [40, 255]}
    blob: {min_circularity: 1.5}
  - name: blue
    colr: [1, 2, 3]
"""


def test_a_missing_config_file_gives_the_cli_message(tmp_path):
    missing = tmp_path / "missing.yaml"
    expected = cli_error("config", "--check", str(missing))
    with pytest.raises(softsight.InputError) as error:
        softsight.load_config(missing)
    assert str(error.value) == expected
    assert expected.startswith(str(missing))


def test_unknown_key_and_bad_value_give_the_cli_message_from_file_and_dict(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(BAD_KEY)
    expected = cli_error("track", "-c", str(path), "-i", "synth:bending", "-o", str(tmp_path / "x.csv"))
    assert expected == f"{path}:4: markers[0].blob.min_circularity: 1.5 must lie within 0..1"
    for call in (softsight.load_config, softsight.Session,
                 lambda c: softsight.track("synth:bending", c)):
        with pytest.raises(softsight.InputError) as error:
            call(str(path))
        assert str(error.value) == expected
    # The dict with the same keys: the same message, the dict named instead of file and line.
    config = {"markers": [{"name": "red", "hsv": {"h": [170, 10], "s": [80, 255], "v": [40, 255]},
                           "blob": {"min_circularity": 1.5}},
                          {"name": "blue", "colr": [1, 2, 3]}]}
    with pytest.raises(softsight.InputError) as error:
        softsight.load_config(config)
    assert str(error.value) == expected.replace(f"{path}:4:", "<dict>:")
    # The unknown key, once the value is fixed.
    path.write_text(BAD_KEY.replace("1.5", "0.5"))
    expected = cli_error("config", "--check", str(path))
    assert "colr" in expected and expected.startswith(f"{path}:6:")
    config["markers"][0]["blob"]["min_circularity"] = 0.5
    with pytest.raises(softsight.InputError) as error:
        softsight.load_config(config)
    assert str(error.value) == expected.replace(f"{path}:6:", "<dict>:")


def test_a_dict_config_is_the_same_config_as_its_file(markers_yaml, tmp_path):
    from_file = softsight.load_config(markers_yaml)
    from_file.save(tmp_path / "a.yaml")
    config = {
        "markers": [
            {"name": "red", "hsv": {"h": [170, 10], "s": [80, 255], "v": [40, 255]}},
            {"name": "blue", "hsv": {"h": [100, 130], "s": [80, 255], "v": [40, 255]}},
            {"name": "green", "hsv": {"h": [45, 85], "s": [80, 255], "v": [40, 255]}},
        ],
        "triple": ["red", "blue", "green"],
        "scale_mm_per_px": 0.25,
    }
    from_dict = softsight.load_config(config)
    from_dict.save(tmp_path / "b.yaml")
    assert (tmp_path / "a.yaml").read_text() == (tmp_path / "b.yaml").read_text()
    assert from_dict.marker_names == ["red", "blue", "green"]
    assert from_dict.triple == ("red", "blue", "green") and from_dict.metric
    assert from_dict.columns == from_file.columns
    assert "blue_status" in from_dict.columns and "tip_disp_mm" in from_dict.columns
    # Pickles as its source (what a Dask worker receives), re-checked on load.
    again = pickle.loads(pickle.dumps(from_dict))
    assert again.columns == from_dict.columns and again.source == config
    config["markers"][0]["name"] = "changed"  # The config kept its own copy.
    assert pickle.loads(pickle.dumps(from_dict)).marker_names[0] == "red"
    assert softsight.load_config(markers_yaml, method="zncc").methods["red"] == "zncc"


def test_values_of_the_wrong_type_in_a_dict():
    # The type's name with its article as it is said ("a ellipsis" was the issue's).
    with pytest.raises(softsight.InputError, match=r"^<dict>: markers\[0\]\.hsv: an object cannot be"):
        softsight.load_config({"markers": [{"name": "red", "hsv": object()}]})
    with pytest.raises(softsight.InputError, match=r"^<dict>: markers\[0\]\.hsv: an ellipsis cannot be"):
        softsight.load_config({"markers": [{"name": "red", "hsv": ...}]})
    with pytest.raises(softsight.InputError, match=r"^<dict>: markers\[0\]\.hsv: a set cannot be"):
        softsight.load_config({"markers": [{"name": "red", "hsv": {1}}]})
    with pytest.raises(softsight.InputError, match=r"^<dict>: markers: key 3 is not a string"):
        softsight.load_config({"markers": {3: "x"}})
    with pytest.raises(TypeError, match=r"got an int$"):
        softsight.load_config(42)
    markers = [{"name": "red", "hsv": {"h": [170, 10], "s": [80, 255], "v": [40, 255]}}]
    # A str is text, even when it spells a number; None is no value (it used to drop the mm
    # columns silently).
    with pytest.raises(softsight.InputError,
                       match=r"^<dict>:.*scale_mm_per_px: expected a number, got the string '0.25'"):
        softsight.load_config({"markers": markers, "scale_mm_per_px": "0.25"})
    with pytest.raises(softsight.InputError, match=r"^<dict>: scale_mm_per_px: None is not a config"):
        softsight.load_config({"markers": markers, "scale_mm_per_px": None})
    assert "tip_disp_mm" not in softsight.load_config({"markers": markers}).columns


def test_version_and_licence_agree_with_the_program():
    assert run_cli("--version").stdout.strip() == f"softsight {softsight.__version__}"
    assert softsight.__license__ == "Apache-2.0"
    # The package metadata beside the module (build tree and installed alike).
    assert importlib.metadata.version("softsight") == softsight.__version__
    assert importlib.metadata.metadata("softsight")["License"] == "Apache-2.0"


def test_a_dict_that_contains_itself_or_nests_too_deep_is_an_input_error():
    looped = {"markers": []}
    looped["markers"].append({"name": "a", "colour": looped})
    deep = {"markers": []}
    inner = deep
    for _ in range(30000):
        inner["x"] = {}
        inner = inner["x"]
    for config in (looped, deep):
        for call in (softsight.load_config, softsight.Session):
            with pytest.raises(softsight.InputError) as error:
                call(config)
            assert "nested deeper than 64" in str(error.value)


def test_save_into_another_folder_keeps_naming_the_template_file(tmp_path):
    import numpy as np
    import cv2
    here = tmp_path / "here"
    there = tmp_path / "there" / "deeper"
    here.mkdir()
    there.mkdir(parents=True)
    image = np.zeros((21, 21, 3), np.uint8)
    cv2.circle(image, (10, 10), 6, (0, 0, 255), -1)
    cv2.imwrite(str(here / "dot.png"), image)
    (here / "m.yaml").write_text("markers:\n  - name: dot\n    method: zncc\n"
                                 "    template: {file: dot.png}\n")
    config = softsight.load_config(here / "m.yaml")
    config.save(there / "copy.yaml")
    text = (there / "copy.yaml").read_text()
    assert "../../here/dot.png" in text
    again = softsight.load_config(there / "copy.yaml")  # Finds the image from its new folder.
    assert again.methods["dot"] == "zncc"
