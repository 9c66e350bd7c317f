"""Seeded fuzz of the replay page (issue 22, security): hostile strings in every string field that
reaches ``replay.html`` leave its element structure unchanged (parsed with a real HTML parser,
``html.parser``), and its data parses back to the same strings.

The pages are built in-process from replay data of a scene's unloaded state (no simulation per
case): the strings are put straight into the data dict given to :func:`replay_html`, which
must be safe for any string, whatever the scene loader refuses upstream.
"""

from __future__ import annotations

import copy
import json
import random
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

import coopctrl
from coopctrl.replay import replay_data, replay_html
from coopctrl.replay.page import fill, html_text, script_json
from coopctrl.replay.urdf_visuals import urdf_arm_visuals
from plants.arms.named_robots import urdf_path

from _replay_data import still_result

REPO = Path(__file__).resolve().parents[1]

#: Pieces that break a page built by naive text substitution: script and comment ends, the
#: page's own markers, quotes, entities, line separators, control characters, lone surrogates.
HOSTILE = ("</script>", "</SCRIPT >", "<script>", "<!--", "-->", "<!--<script>", "__DATA__", "__THREE__",
           "__TITLE__", "</title>", "<title>", "<style>", "<b onmouseover=alert(1)>", "\"", "'", "`", "${x}",
           "&amp;", "&lt;", "&#60;", "&", "<", ">", "\\", "\\u003c", "\u2028", "\u2029", "\x00", "\x1b]0;pwned\x07",
           "\x1b[2J", "\r\n", "\t", "\ud800", "\udfff", "\ufeff", "\U0001F600", "]]>", "<![CDATA[", "/", "*/", "/*")


def hostile_string(rng: random.Random) -> str:
    return "".join(rng.choice(HOSTILE) if rng.random() < 0.7 else rng.choice("ab z.-_") for _ in range(rng.randint(1, 6)))


class Structure(HTMLParser):
    """The tag sequence of a page (start, end and self-closing tags with their attribute
    names), the text of ``<title>`` and the text of each ``<script>``."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags, self.title, self.scripts, self.inside = [], "", [], None

    def handle_starttag(self, tag, attrs):
        self.tags.append(("start", tag, tuple(name for name, _ in attrs)))
        self.inside = tag
        if tag == "script":
            self.scripts.append("")

    def handle_startendtag(self, tag, attrs):
        self.tags.append(("startend", tag, tuple(name for name, _ in attrs)))

    def handle_endtag(self, tag):
        self.tags.append(("end", tag))
        self.inside = None

    def handle_data(self, data):
        if self.inside == "title":
            self.title += data
        elif self.inside == "script":
            self.scripts[-1] += data

    def handle_comment(self, data):
        self.tags.append(("comment",))


def parse(page: str) -> Structure:
    s = Structure()
    s.feed(page)
    s.close()
    return s


def page_data(structure: Structure):
    """The JSON of the ``var DATA = ...;`` script, parsed."""
    (text,) = [s for s in structure.scripts if s.lstrip().startswith("var DATA = ")]
    return json.loads(text.strip()[len("var DATA = "):].rstrip(";"))


def strings_replaced(value, rng):
    """``value`` with every string (not the keys) replaced by a hostile one."""
    if isinstance(value, str):
        return hostile_string(rng)
    if isinstance(value, dict):
        return {k: strings_replaced(v, rng) for k, v in value.items()}
    if isinstance(value, list):
        return [strings_replaced(v, rng) for v in value]
    return value


def string_fields(value, path="data"):
    if isinstance(value, str):
        yield path
    elif isinstance(value, dict):
        for k, v in value.items():
            yield from string_fields(v, f"{path}.{k}")
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from string_fields(v, f"{path}[{i}]")


@pytest.fixture(scope="module")
def base_data():
    """Replay data of the two Pandas at rest (4 frames): its strings are the scene name, status,
    reason, space, integrator, arm models and labels, URDF link names of bodies and visuals."""
    scenario = coopctrl.load_scenario(REPO / "scenarios" / "two_panda_carry.toml")
    data = replay_data(still_result(scenario, [0.0, 0.01, 0.02, 0.03], status="diverged", reason="why"), scenario)
    data["notes"] = ["a note"]
    return data


@pytest.fixture(scope="module")
def reference(base_data):
    return parse(replay_html(base_data))


def test_base_page_has_its_structure(base_data, reference):
    fields = set(re.sub(r"\[\d+\]", "[]", p) for p in string_fields(base_data))
    # the fuzz reaches every kind of string field of the page's data
    for field in ("data.scenario", "data.status", "data.reason", "data.space", "data.integrator", "data.arm_models[]",
                  "data.arm_labels[]", "data.arm_links[][]", "data.arm_visuals[][].link", "data.arm_visuals[][].shape",
                  "data.notes[]"):
        assert field in fields, field
    assert [t[1] for t in reference.tags if t[0] == "start"].count("script") == 3
    assert page_data(reference) == json.loads(json.dumps(base_data))
    assert reference.title == f"{base_data['scenario']} replay ({base_data['status']})"


def test_hostile_strings_in_every_field_leave_the_structure(base_data, reference):
    rng = random.Random(20261201)
    for case in range(25):
        data = strings_replaced(base_data, rng)
        page = replay_html(data)
        got = parse(page)
        assert got.tags == reference.tags, f"case {case}: {data['scenario']!r}"
        assert page_data(got) == json.loads(json.dumps(data)), f"case {case}"
        # html.parser does not model the browsers' "script data escaped" states, which '<!--' and
        # '<script' open: the data script holds no '<' at all, so no browser enters them
        assert "<" not in [s for s in got.scripts if s.lstrip().startswith("var DATA")][0]
        # the markers are replaced once, in the template only: the data is inserted as it is
        assert page.count("var DATA = ") == 1 and page.split("var DATA = ", 1)[1].startswith(script_json(data) + ";\n")
        page.encode("utf-8")  # writable as UTF-8 even with lone surrogates in the strings


def test_each_hostile_piece_as_the_name(base_data, reference):
    for piece in HOSTILE:
        data = dict(base_data, scenario=f"x{piece}y", reason=piece)
        got = parse(replay_html(data))
        assert got.tags == reference.tags, repr(piece)
        assert page_data(got)["scenario"] == f"x{piece}y"


def test_script_json_escapes_what_closes_a_script():
    text = script_json({"s": "</script><!--\u2028\u2029&>"})
    assert not re.search("[<>&\u2028\u2029]", text)
    assert json.loads(text) == {"s": "</script><!--\u2028\u2029&>"}
    with pytest.raises(ValueError):
        script_json({"x": float("nan")})


def test_html_text_escapes_markup_and_shows_controls():
    assert html_text('<a href="x">&\'') == "&lt;a href=&quot;x&quot;&gt;&amp;&#x27;"
    assert html_text("bell\x07 esc\x1b") == "bell\\x07 esc\\x1b"
    assert html_text("\ud800é") == "\\ud800&#233;"


def test_markers_are_filled_in_one_pass():
    # an inserted value holding a marker is not searched again
    assert fill("<t>__TITLE__</t>__THREE__|__DATA__", {"TITLE": "__DATA__", "THREE": "__TITLE__", "DATA": "d"}) == \
        "<t>__DATA__</t>__TITLE__|d"
    with pytest.raises(ValueError, match="exactly once"):
        fill("__TITLE__ __TITLE__ __THREE__ __DATA__", {"TITLE": "", "THREE": "", "DATA": ""})


def test_hostile_urdf_link_names_and_mesh_paths(tmp_path, base_data, reference):
    """A user's URDF whose link names and mesh file name carry markup reaches the page as text."""
    rng = random.Random(7)
    text = Path(urdf_path("panda")).read_text(encoding="utf-8")
    names = {}
    for link in ("panda_link0", "panda_link3", "panda_hand_tcp"):
        names[link] = f"{link}{hostile_string(rng)}".replace("\x00", "").replace("\x1b", "").replace("\x07", "") \
            .replace("\ud800", "").replace("\udfff", "")  # XML cannot hold these at all
        names[link] = re.sub(r"\s", "_", names[link])  # XML normalizes white space in attributes
        text = text.replace(f'"{link}"', '"' + names[link].replace("&", "&amp;").replace("<", "&lt;")
                            .replace('"', "&quot;").replace(">", "&gt;") + '"')
    text = text.replace('<geometry><box size="0.06 0.2 0.065"/></geometry>',
                        '<geometry><mesh filename="package://x/&lt;/script&gt;&lt;!--.stl"/></geometry>')
    urdf = tmp_path / "hostile.urdf"
    urdf.write_text(text, encoding="utf-8")
    shapes = urdf_arm_visuals(urdf, names["panda_link0"], names["panda_hand_tcp"])
    assert shapes.links[0] == names["panda_link0"] and shapes.links[3] == names["panda_link3"]
    assert any("</script><!--.stl" in n for n in shapes.notes)  # the mesh is not at hand: said why
    data = copy.deepcopy(base_data)
    data["arm_links"][0] = list(shapes.links)
    data["notes"] = list(shapes.notes)
    got = parse(replay_html(data))
    assert got.tags == reference.tags
    assert page_data(got)["arm_links"][0] == list(shapes.links)
