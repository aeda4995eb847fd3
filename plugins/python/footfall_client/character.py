"""Character files (data/characters/*.json) as the plugins need them: foot names and offsets,
the foot pairs that share a central locator, and the walk settings a panel may override.
Pure Python; footfall's frame (Y up, the character facing +Z, +X its left)."""

import json
import math
import os
import re
import stat

from .session import INVALID_ARGUMENT, FootfallError

# Walk settings a panel can override: panel name -> character file key.
OVERRIDES = {"step_length": "step_length", "step_height": "step_height",
             "frames_per_step": "frames_per_step", "foot_length": "foot_length"}


def read_text(path, what="file"):
    """The text of the regular file at `path`; FootfallError io_error when it cannot be read,
    invalid_argument for a directory, FIFO or device (opening a FIFO waits for a writer: the
    DCC would hang)."""
    shown = path if path else "''"
    try:
        mode = os.stat(path).st_mode
        if not stat.S_ISREG(mode):
            raise FootfallError(INVALID_ARGUMENT, "%s: cannot open %s: not a regular file"
                                % (shown, what), what)
        with open(path, encoding="utf-8") as f:
            return f.read()
    except OSError as e:
        raise FootfallError(5, "%s: cannot open %s: %s" % (shown, what, e.strerror or e),
                            what) from None
    except UnicodeDecodeError as e:
        raise FootfallError(6, "%s: not UTF-8 text (byte %d)" % (shown, e.start), what) from None


# Nesting deeper than this is refused in character and walk files (theirs is 4 or 5 levels):
# Python's JSON reader recurses once a level, and ran out of stack (RecursionError) on a file
# nested some hundreds of levels deep, fewer on the deeper stack of a DCC's command.
MAX_JSON_DEPTH = 64

# A string, or one never closed to the end of the text (a lone backslash last included): every
# match attempt succeeds at its first quote, so removing strings takes one pass (a text of
# escaped quotes in a string never closed made each quote scan to the end: 200 KB took minutes).
_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*(?:"|\\?\Z)', re.S)
_NOT_BRACKET = re.compile(r"[^\[\]{}]+")
_INNERMOST = re.compile(r"\[\]|\{\}")


def _deeper(brackets, levels):
    """True when `brackets` (a JSON text's brackets only) nest more than `levels` deep. Each
    pass removes the innermost pairs in one regular-expression substitution: a long walk file
    costs a few passes, not a Python loop over its text."""
    for _ in range(levels):
        brackets, removed = _INNERMOST.subn("", brackets)
        if not removed:
            return False
    return bool(_INNERMOST.search(brackets))


def _nested_deeper_than(text, levels):
    """True when the JSON text nests arrays and objects more than `levels` deep. Its brackets
    are counted first strings and all (fast), and a text that looks too deep is looked at
    again without its strings (skipping strings takes a tenth of a second for 4 MB of walk).
    (Brackets in strings may hide nesting from the first look: json.loads's RecursionError
    is the backstop.)"""
    if not _deeper(_NOT_BRACKET.sub("", text), levels):
        return False
    return _deeper(_NOT_BRACKET.sub("", _JSON_STRING.sub("", text)), levels)


def parse_json(text, name="JSON", call="json"):
    """JSON text as Python values, read as footfall's C++ reader reads it: a UTF-8 byte order
    mark at the start is skipped. FootfallError parse_error naming `name` for malformed JSON
    or JSON nested deeper than MAX_JSON_DEPTH levels."""
    if text.startswith("\ufeff"):
        text = text[1:]
    too_deep = FootfallError(6, "%s: nested deeper than %d levels" % (name, MAX_JSON_DEPTH), call)
    if _nested_deeper_than(text, MAX_JSON_DEPTH):
        raise too_deep
    try:
        return json.loads(text)
    except ValueError as e:
        raise FootfallError(6, "%s: %s" % (name, e), call) from None
    except RecursionError:  # (malformed: brackets never closed)
        raise too_deep from None


def read_json(path, what="file"):
    """The JSON value of the file at `path` (see read_text and parse_json)."""
    return parse_json(read_text(path, what), path, what)


def load(path):
    """The character file at `path` as a dict; FootfallError (io_error/parse_error) otherwise."""
    return parse(read_text(path, "character file"), path)


def parse(text, name="character"):
    data = parse_json(text, name, "character")
    pairs(data, name)  # validates the feet and the pairs
    return data


def _vec(value):
    if isinstance(value, dict):
        value = [value.get(k, 0.0) for k in "xyz"]
    return tuple(float(v) for v in value)


def feet(data, name="character"):
    """[(foot name, (x, y, z) rest position)] in file order: relative to the body's ground
    point, character space (+Z forward, +Y up, +X left)."""
    raw = data.get("feet") if isinstance(data, dict) else None
    if not isinstance(raw, list) or not raw:
        raise FootfallError(INVALID_ARGUMENT, "%s: expected a non-empty \"feet\" list" % name,
                            "character")
    out = []
    for i, foot in enumerate(raw):
        try:
            pos = _vec(foot.get("rest", foot.get("position")))
            foot_name = foot["name"]
            if (not isinstance(foot_name, str) or not foot_name or len(pos) != 3 or
                    not all(math.isfinite(c) for c in pos)):
                raise ValueError
            out.append((foot_name, pos))
        except (AttributeError, KeyError, TypeError, ValueError, OverflowError):
            raise FootfallError(INVALID_ARGUMENT, "%s: feet[%d]: expected {\"name\": NAME, "
                                "\"rest\": [x, y, z]} (a non-empty name, three finite numbers)"
                                % (name, i), "character") from None
        if foot_name in [f[0] for f in out[:-1]]:
            raise FootfallError(INVALID_ARGUMENT, "%s: feet[%d]: the name '%s' is used twice"
                                % (name, i, foot_name), "character")
    return out


def rest_positions(data, name="character"):
    """[(foot name, (x, y, z))] as a walk places the feet: rests less their centroid (the body
    stands over the feet's centroid; the same as feet() for symmetric feet)."""
    fs = feet(data, name)
    c = [sum(p[i] for _, p in fs) / len(fs) for i in range(3)]
    return [(n, (p[0] - c[0], p[1] - c[1], p[2] - c[2])) for n, p in fs]


def display_name(data, fallback):
    """The character's "name", or `fallback` when it has none; FootfallError when "name" is not
    a string."""
    value = data.get("name") if isinstance(data, dict) else None
    if value is None or value == "":
        return fallback
    if not isinstance(value, str):
        raise FootfallError(INVALID_ARGUMENT, "%s: 'name' must be a string, found %s"
                            % (fallback, type(value).__name__), "character")
    return value


def number(data, key, default):
    try:
        return float(data.get(key, default))
    except (TypeError, ValueError, OverflowError):
        return default


def body_height(data):
    """Height of the body above the feet [world units] (the generator's default 0.9)."""
    return number(data, "body_height", 0.9)


def is_biped(data):
    """Bipeds stay upright; multipeds (align_to_normal) take the terrain normal as up."""
    return not bool(data.get("align_to_normal", False))


def pairs(data, name="character"):
    """Foot pairs that share a central locator: the file's "pairs" (groups of foot names), or
    else each left foot (x > 0) with the right foot (x < 0) nearest to its mirror; a foot left
    over stands alone. [(name, [foot names])]. FootfallError for a pair that is empty or names
    a foot the file does not have."""
    fs = feet(data, name)
    given = data.get("pairs")
    if isinstance(given, list) and given:
        names = {f[0] for f in fs}
        for i, group in enumerate(given):
            if not isinstance(group, list) or not group:
                raise FootfallError(INVALID_ARGUMENT, "%s: pairs[%d]: expected a non-empty list "
                                    "of foot names" % (name, i), "character")
            for foot_name in group:
                if foot_name not in names:
                    raise FootfallError(INVALID_ARGUMENT, "%s: pairs[%d]: no foot named %r"
                                        % (name, i, foot_name), "character")
        return [("_".join(str(n) for n in group), [str(n) for n in group]) for group in given]
    left = [f for f in fs if f[1][0] > 0]
    right = [f for f in fs if f[1][0] <= 0]
    out, used = [], set()
    for name, p in left:
        best = None
        for rname, q in right:
            if rname in used:
                continue
            d = math.hypot(p[0] + q[0], p[2] - q[2])
            if best is None or d < best[0]:
                best = (d, rname)
        if best is None:
            out.append((name, [name]))
        else:
            used.add(best[1])
            out.append(("%s_%s" % (name, best[1]), [name, best[1]]))
    for rname, _ in right:
        if rname not in used:
            out.append((rname, [rname]))
    return out


def with_overrides(data, **values):
    """A copy of `data` with the walk settings in `values` (see OVERRIDES) replaced where the
    value is > 0; zero or None keeps the file's value."""
    out = json.loads(json.dumps(data))
    for panel_name, value in values.items():
        key = OVERRIDES[panel_name]
        if value is not None and value > 0:
            out[key] = int(value) if key == "frames_per_step" else float(value)
    return out


# The lengths of a character file (ScaleCharacter, character.h, multiplies the same ones),
# beside its feet's rests.
LENGTHS = ("step_length", "step_height", "body_height", "max_rise", "reach", "foot_length",
           "foot_width")

# Metres in one of each linear unit a DCC may work in (Maya's short and long names).
METRES_PER_UNIT = {"mm": 0.001, "millimeter": 0.001, "cm": 0.01, "centimeter": 0.01,
                   "m": 1.0, "meter": 1.0, "km": 1000.0, "kilometer": 1000.0,
                   "in": 0.0254, "inch": 0.0254, "ft": 0.3048, "foot": 0.3048,
                   "yd": 0.9144, "yard": 0.9144, "mi": 1609.344, "mile": 1609.344}


def unit_scale(from_unit, to_unit):
    """How many `to_unit` make one `from_unit` (100 from "m" to "cm"); ValueError naming the
    unit for one not in METRES_PER_UNIT."""
    for unit in (from_unit, to_unit):
        if unit not in METRES_PER_UNIT:
            raise ValueError("unknown linear unit %r (expected one of %s)"
                             % (unit, ", ".join(sorted(METRES_PER_UNIT))))
    return METRES_PER_UNIT[from_unit] / METRES_PER_UNIT[to_unit]


def scaled(data, factor):
    """A copy of the character `data` with every length multiplied by `factor` (its feet's
    rests and LENGTHS; angles, frames and the gait stay), as `footfall generate --scale` and a
    request's "scale" scale it: a character file in metres in a centimetre scene. Lengths the
    file leaves out keep the generator's defaults, scaled too where they are lengths (max_rise);
    ValueError for a factor that is not a finite number above 0."""
    if not _finite_number(factor) or factor <= 0:
        raise ValueError("a character's scale must be a finite number above 0, not %r"
                         % (factor,))
    out = json.loads(json.dumps(data))
    if factor == 1:
        return out
    for foot in out.get("feet", []):
        if isinstance(foot, dict) and isinstance(foot.get("rest"), list):
            foot["rest"] = [v * factor if _finite_number(v) else v for v in foot["rest"]]
    for key in LENGTHS:
        if _finite_number(out.get(key)):
            out[key] = out[key] * factor
    if "max_rise" not in out:
        out["max_rise"] = DEFAULT_MAX_RISE * factor
    return out


# The units a walk JSON's "unit" may name (footfall/steps/linear_units.h; Maya's short names),
# in the order `footfall generate --unit` lists them.
WALK_UNITS = ("mm", "cm", "m", "km", "in", "ft", "yd", "mi")
# The same units in the order the plugins' "Character file unit" menus list them: metres, the
# shipped characters' unit and the default, first.
UNIT_MENU = ("m", "cm", "mm", "in", "ft", "yd", "km", "mi")

# The generator's max_rise for a character file without one (character.h).
DEFAULT_MAX_RISE = 0.35


def _finite_number(value):
    """Whether a JSON value is a finite number a double holds (an integer of 400 digits, which
    JSON allows, is not: math.isfinite raised OverflowError on it)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def check_walk(walk, name="walk"):
    """Raises ValueError naming the first problem of a footfall walk dict (JSON format
    "footfall-walk", as read from a file), before a plugin keys or creates anything: tracks
    with a name and a kind, keys with a finite frame, increasing along each track, a position
    of three finite numbers and, where given, a rotation of four (a foot's on all its keys or
    on none) and a phase. The header's fields, where given, as footfall's reader takes them:
    "format" "footfall-walk", "version" 1 (a later format is refused, not misread), "fps" a
    positive number. A walk of tracks alone (as read back from a glTF, or written by hand) is
    taken: the plugins key frames and positions, not phases or frame rates."""
    if not isinstance(walk, dict) or not isinstance(walk.get("tracks"), list):
        raise ValueError("%s: expected footfall walk JSON with a \"tracks\" list" % name)
    if "format" in walk and walk["format"] != "footfall-walk":
        raise ValueError("%s: format: expected \"footfall-walk\"" % name)
    if "version" in walk and (not _finite_number(walk["version"]) or walk["version"] != 1):
        raise ValueError("%s: version: expected 1 (a walk of another format version: update "
                         "footfall)" % name)
    if "fps" in walk and (not _finite_number(walk["fps"]) or not walk["fps"] > 0):
        raise ValueError("%s: fps: expected a positive number" % name)
    if "unit" in walk and walk["unit"] not in WALK_UNITS:
        raise ValueError("%s: unit: expected one of %s" % (name, ", ".join(WALK_UNITS)))

    def finite(values, count):
        return (isinstance(values, list) and len(values) == count and
                all(_finite_number(v) for v in values))

    for t, track in enumerate(walk["tracks"]):
        where = "%s: tracks[%d]" % (name, t)
        if not isinstance(track, dict) or not isinstance(track.get("name"), str) or \
                track.get("kind", "foot") not in ("foot", "body"):
            raise ValueError("%s: expected {\"name\": NAME, \"kind\": \"foot\"|\"body\", "
                             "\"keys\": [...]}" % where)
        keys = track.get("keys", [])
        if not isinstance(keys, list):
            raise ValueError("%s.keys: expected a list" % where)
        for k, key in enumerate(keys):
            at = "%s.keys[%d]" % (where, k)
            if not isinstance(key, dict) or not finite([key.get("frame")], 1):
                raise ValueError("%s: expected a finite \"frame\"" % at)
            # (Two keys at one frame: one was keyed over the other, with no word.)
            if k > 0 and not key["frame"] > keys[k - 1]["frame"]:
                raise ValueError("%s.frame: frames must increase along a track (%.15g after "
                                 "%.15g)" % (at, key["frame"], keys[k - 1]["frame"]))
            if "phase" in key and key["phase"] not in ("start", "mid", "end"):
                raise ValueError("%s.phase: expected \"start\", \"mid\" or \"end\"" % at)
            if not finite(key.get("position"), 3):
                raise ValueError("%s: expected \"position\": [x, y, z] (finite numbers)" % at)
            if "rotation" in key and (not finite(key["rotation"], 4) or
                                      not any(key["rotation"])):
                raise ValueError("%s: expected \"rotation\": [x, y, z, w] (finite numbers, not "
                                 "all zero)" % at)
            # A foot's rotations (a walk generated with foot rotations) are on all its keys or
            # on none, as footfall's reader takes them.
            if track.get("kind", "foot") == "foot" and k > 0 and \
                    ("rotation" in key) != ("rotation" in keys[0]):
                raise ValueError("%s: expected a rotation on every key of a foot track or on none "
                                 "(the first key has %s)"
                                 % (at, "one" if "rotation" in keys[0] else "none"))


def walk_in_unit(walk, unit):
    """The walk `walk` (checked by check_walk) with its lengths in `unit` (a METRES_PER_UNIT
    name): its positions and foot lengths and widths converted from the walk's "unit", and "unit" set to
    `unit`. A walk without a "unit" (footfall generate without --unit) is returned as it is, one
    walk unit to one of `unit`."""
    if "unit" not in walk:
        return walk
    factor = unit_scale(walk["unit"], unit)
    out = dict(walk, unit=unit)
    if factor == 1:
        return out
    out["tracks"] = []
    for track in walk["tracks"]:
        track = dict(track)
        for key in ("foot_length", "foot_width"):
            if _finite_number(track.get(key)):
                track[key] = track[key] * factor
        track["keys"] = [dict(key, position=[v * factor for v in key["position"]])
                         for key in track.get("keys", [])]
        out["tracks"].append(track)
    return out


def rig_tracks(walk, feet, has_body, name="walk"):
    """The names of the foot tracks with keys of a checked walk dict that go onto a rig whose
    feet are `feet` (names), and whether its body track with keys goes onto the rig's body
    (`has_body`). Raises ValueError when the walk keys a foot the rig does not have (another
    character's walk: its body track alone would have gone on, and the rig's feet been cleared),
    or nothing of the rig."""
    walk_feet = [t["name"] for t in walk["tracks"]
                 if t.get("kind", "foot") == "foot" and t.get("keys")]
    body = has_body and any(t.get("kind") == "body" and t.get("keys") for t in walk["tracks"])
    if not body and not any(n in feet for n in walk_feet):
        raise ValueError("%s has no track for this rig's feet or body" % name)
    foreign = [n for n in walk_feet if n not in feet]
    if foreign:
        raise ValueError("%s keys feet this rig does not have (%s; the rig's: %s): it is "
                         "another character's walk; import it with no rig active, onto new "
                         "objects" % (name, ", ".join(foreign), ", ".join(feet) or "none"))
    return walk_feet, body


# The generator's advice to a biped on ground across its up names the request's "up" field
# (generator_setup.cpp), which the plugins never set: the scene's up axis is footfall's up.
_UP_ADVICE = re.compile(r"; if the terrain's up is not \([^()]*\), give the world up with "
                        r"request: 'up' \([^()]*\)")


def in_scene_terms(message, scene_up):
    """`message` (a generate failure's) with advice a plugin's user cannot follow, to give the
    request's "up", said as they can: the scene's up axis `scene_up` ("Z" in Blender, "Y" in
    Maya) is a biped's up, so its ground must face that way."""
    return _UP_ADVICE.sub("; a biped stands upright along the scene's %s axis: turn the terrain "
                          "so that its ground faces +%s" % (scene_up, scene_up), message)
