"""``replay.html``: one self-contained page (three.js inlined, no network) that replays a run.

The page is ``page.html`` with three.js (``vendor/three.min.js``, r160, MIT) and the frames of
:func:`coopctrl.replay.scene_frames.replay_data` inlined. It plays, pauses, steps with a time
slider and changes speed; ``replay.html#frame=N`` (or ``#t=SECONDS``: the frame nearest that
time) opens paused on a frame.

No string of a scene or a result can change the page's structure: every inserted value is
escaped for its context (:func:`html_text` in the ``<title>``, :func:`script_json` for the data
inside ``<script>``), and the markers ``__TITLE__``, ``__THREE__``, ``__DATA__`` are replaced in
one pass over the template (:func:`fill`), so inserted text is never searched for markers.
"""

from __future__ import annotations

import html
import json
import re
import unicodedata
from importlib import resources
from pathlib import Path

from coopctrl.io.atomic import atomic_write

#: The markers of ``page.html``, each present exactly once.
MARKERS = ("TITLE", "THREE", "DATA")
_MARKER = re.compile(r"__(" + "|".join(MARKERS) + r")__")

#: Characters that JSON leaves as they are but that matter inside an HTML ``<script>`` (``<``
#: opens ``</script>`` and ``<!--``; ``>`` and ``&`` for good measure) or to old JavaScript
#: parsers (U+2028, U+2029 end a line): written as ``\\uXXXX`` escapes, which JSON reads back
#: as the same characters.
_SCRIPT_UNSAFE = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026", "\u2028": "\\u2028", "\u2029": "\\u2029"}


def _asset(name: str) -> str:
    return resources.files("coopctrl.replay").joinpath(name).read_text(encoding="utf-8")


def script_json(value) -> str:
    """``value`` as JSON safe to place inside ``<script>``: ASCII only (lone surrogates become
    ``\\udXXX`` escapes), with :data:`_SCRIPT_UNSAFE` escaped. ``json.loads`` of the result
    equals ``json.loads(json.dumps(value))``. NaN and infinities are refused (ValueError)."""
    text = json.dumps(value, separators=(",", ":"), allow_nan=False, ensure_ascii=True)
    return re.sub("[<>&\u2028\u2029]", lambda m: _SCRIPT_UNSAFE[m.group(0)], text)


def html_text(value: str) -> str:
    """``value`` as HTML text (element content or a quoted attribute): ``& < > " '`` escaped;
    control characters, lone surrogates and non-characters shown as ``\\x1b``-style escapes (they
    have no place in HTML text); other non-ASCII as numeric character references."""
    def visible(ch: str) -> str:
        if unicodedata.category(ch) in ("Cc", "Cs", "Cn") and ch not in "\t\n":
            return f"\\x{ord(ch):02x}" if ord(ch) < 0x100 else f"\\u{ord(ch):04x}"
        return ch

    shown = "".join(visible(ch) for ch in str(value))
    return html.escape(shown, quote=True).encode("ascii", "xmlcharrefreplace").decode("ascii")


def fill(template: str, values: dict) -> str:
    """``template`` with each ``__NAME__`` marker replaced by ``values[NAME]`` in one pass: the
    inserted text is never searched again. Every marker of :data:`MARKERS` must occur once."""
    found = _MARKER.findall(template)
    if sorted(found) != sorted(MARKERS):
        raise ValueError(f"page template markers {found}: each of {list(MARKERS)} exactly once")
    return _MARKER.sub(lambda m: values[m.group(1)], template)


def replay_html(data: dict) -> str:
    """The page for the frames ``data`` (a dict of :func:`~coopctrl.replay.scene_frames.replay_data`).

    Raises:
        TypeError: ``data`` is not a dict.
        ValueError: ``data`` holds NaN or an infinity (the page's data is JSON).
    """
    if not isinstance(data, dict):
        raise TypeError(f"data = {type(data).__name__} is invalid: a dict of coopctrl.replay.replay_data")
    three = _asset("vendor/three.min.js").replace("</script", "<\\/script")
    title = html_text(f"{data.get('scenario', '')} replay ({data.get('status', '')})")
    return fill(_asset("page.html"), {"TITLE": title, "THREE": three, "DATA": script_json(data)})


def write_replay(result, scenario, directory: str | Path) -> Path:
    """Write ``replay.html`` into ``directory`` atomically and return its path. With it,
    ``scenario.toml`` (the resolved scenario, :func:`coopctrl.scenario.to_toml.scenario_toml`)
    so that ``coopctrl view DIR`` can rebuild the page later."""
    from coopctrl.replay.scene_frames import replay_data
    from coopctrl.scenario.to_toml import scenario_toml

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    text = replay_html(replay_data(result, scenario))
    path = directory / "replay.html"
    with atomic_write(path, "w", encoding="utf-8") as f:
        f.write(text)
    with atomic_write(directory / "scenario.toml", "w", encoding="utf-8") as f:
        f.write(scenario_toml(scenario))
    return path
