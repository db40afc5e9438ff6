# SPDX-License-Identifier: GPL-2.0-or-later
"""The law's options in one table: each option's values, the law's default (docs/law.md) and
how each engine spells it, with the engine's own default where it differs.

The engine-free part of the options a scene sets (reset, slip timing) is pyref's
(pyref.laws.OPTIONS: pyref knows no engine); this table adds the options only some engines
let a user choose (the history's rotation, the lever arm, the damping's form, the record,
the history of a pair that has opened) and every engine's words. The adapters and the
contract's drivers write an engine's words with words() or arguments(); the README's table
of options is rendered from here (readme_rows, checked by tests/test_law_options.py, which
also reads each C++ plugin's own keyword table and each engine's page against this one).

The LAMMPS 2021 styles default to stock `gran/hooke/history` (reset total, the history
projected, the radii as lever arms, mass-scaled damping), so that the styles renamed in a
stock input change no bit of its run; every other engine defaults to the law's rules.

    python -m stickslip.law_options     prints the README's rows
"""
from __future__ import annotations

from dataclasses import dataclass, field

from pyref.laws import OPTIONS as SCENE_OPTIONS

# the engines, in the README table's order of columns
ENGINES = ("liggghts", "lammps_granular", "lammps", "yade", "deme", "pyref")
TITLES = {"liggghts": "LIGGGHTS", "lammps_granular": "LAMMPS granular", "lammps": "LAMMPS", "yade": "YADE",
          "deme": "DEM-Engine", "pyref": "scene file (pyref, CLI)"}
KINDS = ("keyword", "on_off", "suffix", "argument", "scene", "fixed")


@dataclass(frozen=True)
class Spelling:
    """How one engine selects one option. kind:
    - "keyword": the words `key value` (LAMMPS 2021's keywords, LIGGGHTS' settings that take a value);
    - "on_off": `key on` selects the value `on`, `key off` the other (LIGGGHTS' settings);
    - "suffix": the style's name carries `key` for the value `on`, nothing for the other
      (LAMMPS 2025's sub-model);
    - "argument": a Python keyword argument `key=value` (True/False with `on`);
    - "scene": the scene file's `key = "value"` under [contact];
    - "fixed": no choice: the engine always does `default`.
    `default`: what the engine does when not told. `words`: words of its own for some values
    (a host's other model names). `host`: the setting is the host engine's own, not the
    plugin's (its C++ does not parse it). `note`: what the README says beside it."""
    kind: str
    default: str
    key: str = ""
    on: str = ""
    words: dict = field(default_factory=dict)
    host: bool = False
    note: str = ""
    function: str = ""  # the function an argument belongs to, where the page names it (attach)

    def __post_init__(self):
        assert self.kind in KINDS, self.kind

    def argument(self, value):
        """An argument's Python value for `value`: True/False where it has `on`, else the value."""
        return value == self.on if self.on else value

    def say(self, value):
        """The engine's words for `value` ("" where a suffix is left out; None: fixed)."""
        if self.kind == "fixed":
            return None
        if value in self.words:
            return self.words[value]
        if self.kind == "keyword":
            return f"{self.key} {value}"
        if self.kind == "on_off":
            return f"{self.key} {'on' if value == self.on else 'off'}"
        if self.kind == "suffix":
            return self.key if value == self.on else ""
        if self.kind == "argument":
            given = self.argument(value)
            return f'{self.key}="{given}"' if isinstance(given, str) else f"{self.key}={given}"
        return f'{self.key} = "{value}"'


@dataclass(frozen=True)
class Option:
    name: str
    values: tuple  # the law's default first
    title: str  # the README's name of the option
    meaning: str  # what it chooses (the README's words)
    phrases: dict  # value -> the words a page uses to state it (e.g. a default without suffixes)
    spellings: dict  # engine -> Spelling

    @property
    def default(self):
        return self.values[0]


def _same_everywhere(spellings, fixed):
    """`spellings`, and `fixed` for every engine they leave out: the engines without the option."""
    return {e: spellings.get(e, fixed) for e in ENGINES}


_RESET, _TIMING = SCENE_OPTIONS["reset"], SCENE_OPTIONS["slip_timing"]
OPTIONS = {o.name: o for o in (
    Option("reset", _RESET, "reset",
           "at a slip, the spring alone carries Fmin (`spring`, eq. 8) or spring + dashpot (`total`)",
           {"spring": "the spring alone carries Fmin", "total": "spring and dashpot together carry Fmin"},
           {"liggghts": Spelling("on_off", "spring", "slip_reset_total", on="total"),
            "lammps_granular": Spelling("suffix", "spring", "/total", on="total"),
            "lammps": Spelling("keyword", "total", "reset", note="stock's rescale"),
            "yade": Spelling("argument", "spring", "reset"),
            "deme": Spelling("argument", "spring", "reset", function="attach"),
            "pyref": Spelling("scene", "spring", "reset")}),
    Option("slip_timing", _TIMING, "slip timing",
           "slip tested at the end of the step (`step`, the paper) or each slip at its time inside it (`exact`)",
           {"step": "tested at the end of the step", "exact": "each slip at its time inside the step"},
           {"liggghts": Spelling("on_off", "step", "exact_slip_timing", on="exact"),
            "lammps_granular": Spelling("suffix", "step", "/exact", on="exact"),
            "lammps": Spelling("keyword", "step", "slip_timing"),
            "yade": Spelling("argument", "step", "slip_timing"),
            "deme": Spelling("argument", "step", "slip_timing", function="attach"),
            "pyref": Spelling("scene", "step", "slip_timing")}),
    Option("history_rotation", ("keep_length", "project"), "history rotation",
           "the spring turned into the new tangent plane keeping its length, or projected (stock)",
           {"keep_length": "turned keeping its length", "project": "projected"},
           _same_everywhere({"liggghts": Spelling("keyword", "keep_length", "history_rotation"),
                             "lammps": Spelling("keyword", "project", "history_rotation")},
                            Spelling("fixed", "keep_length"))),
    Option("lever_arm", ("contact", "radius"), "lever arm",
           "torques and contact velocity at the middle of the overlap, or at the radii (stock)",
           {"contact": "the middle of the overlap", "radius": "the radius"},
           _same_everywhere({"lammps_granular": Spelling("fixed", "radius", note="LAMMPS' granular model"),
                             "lammps": Spelling("keyword", "radius", "lever_arm")},
                            Spelling("fixed", "contact"))),
    Option("damping", ("absolute", "mass"), "damping",
           "the dashpots ν_n, ν_s in N·s/m, or rates scaled by the effective mass (stock)",
           {"absolute": "absolute", "mass": "scaled by the effective mass"},
           _same_everywhere({"liggghts": Spelling("on_off", "mass", "absolute_damping", on="absolute", host=True,
                                                  note="`hooke/stiffness`'s"),
                             "lammps_granular": Spelling("keyword", "viscoelastic", "damping", host=True,
                                                         words={"absolute": "damping velocity",
                                                                "mass": "damping mass_velocity"},
                                                         note="the damping sub-model's"),
                             "lammps": Spelling("keyword", "mass", "damping")},
                            Spelling("fixed", "absolute"))),
    Option("record", ("no", "yes"), "record",
           "each contact keeps what the law applied (Fn, F_s), its slip count and work",
           {"no": "no record", "yes": "the record kept"},
           _same_everywhere({"liggghts": Spelling("on_off", "no", "stick_slip_record", on="yes"),
                             "lammps_granular": Spelling("suffix", "no", "/record", on="yes"),
                             "lammps": Spelling("keyword", "no", "record"),
                             "deme": Spelling("argument", "no", "record", on="yes", function="attach"),
                             "yade": Spelling("fixed", "yes", note="the law's contact()")},
                            Spelling("fixed", "yes", note="[output] contacts"))),
    Option("history_on_separation", ("drop", "keep"), "history on separation",
           "a grain pair's spring dropped when it opens, or kept until the neighbour list drops the pair (stock)",
           {"drop": "dropped", "keep": "kept"},
           _same_everywhere({"liggghts": Spelling("keyword", "drop", "history_on_separation")},
                            Spelling("fixed", "drop"))),
)}
# the options the README's table of parameters shows (damping: in its ν_n and ν_s rows)
README_ROWS = ("reset", "slip_timing", "history_rotation", "lever_arm")


def the_law(**values):
    """Every option at the law's rule (docs/law.md: each option's first value), `values` changed."""
    return {name: o.default for name, o in OPTIONS.items()} | values


def check(engine, name, value):
    """ValueError naming the option and its allowed values, or the one value `engine` has."""
    if name not in OPTIONS:
        raise ValueError(f"{name}: not an option of the law (options: {', '.join(OPTIONS)})")
    option = OPTIONS[name]
    if value not in option.values:
        raise ValueError(f"{name} = {value!r}: must be one of {', '.join(option.values)}")
    s = option.spellings[engine]
    if s.kind == "fixed" and value != s.default:
        raise ValueError(f"{name} = {value!r}: {TITLES[engine]} has {s.default} only")


def words(engine, explicit=False, **values):
    """The words that select `values` (option name -> value) on `engine`, in the table's order:
    a list of each option's words, left out where the value is the engine's default unless
    `explicit`, and for options the engine does not let choose (checked: the value must be
    the one it has)."""
    for name, value in values.items():
        check(engine, name, value)
    out = []
    for name, option in OPTIONS.items():
        s = option.spellings[engine]
        said = s.say(values[name]) if name in values else None
        if said and (explicit or values[name] != s.default):
            out.append(said)
    return out


def arguments(engine, **values):
    """`values` as the keyword arguments of a Python engine's functions (YADE, DEM-Engine):
    {argument: value} for the options the engine lets choose (the others checked)."""
    for name, value in values.items():
        check(engine, name, value)
    spelt = {name: OPTIONS[name].spellings[engine] for name in values}
    return {s.key: s.argument(values[name]) for name, s in spelt.items() if s.kind == "argument"}


def sub_model(**values):
    """LAMMPS 2025's tangential sub-model name for `values`: stick_slip and its suffixes."""
    return "stick_slip" + "".join(words("lammps_granular", **values))


def cell(option, engine):
    """The README's cell for an engine: its spelling, then its default (bold where it is not
    the law's), or what it always does."""
    s = option.spellings[engine]
    default = s.default if s.default == option.default else f"**{s.default}**"
    note = f" ({s.note})" if s.note else ""
    if s.kind == "fixed":
        return default + note
    if s.kind in ("on_off", "suffix"):  # (the words select one value: the other is the default)
        return f"`{s.key}{' on' if s.kind == 'on_off' else ''}`: {s.on}; {default}{note}"
    how = f"`{s.function}({s.key}=)`" if s.function else f"`{s.key}=`" if s.kind == "argument" else f"`{s.key}`"
    return f"{how}, {default}{note}"


def readme_rows():
    """The README's rows of the options (its table of parameters: symbol, meaning, unit,
    allowed, then an engine a column)."""
    rows = []
    for name in README_ROWS:
        o = OPTIONS[name]
        rows.append("| " + " | ".join([o.title, o.meaning, "—", ", ".join(o.values)]
                                      + [cell(o, e) for e in ENGINES]) + " |")
    return rows


if __name__ == "__main__":
    print("\n".join(readme_rows()))
