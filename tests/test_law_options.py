# SPDX-License-Identifier: GPL-2.0-or-later
"""The table of the law's options (stickslip/law_options.py) against what each engine does:
the C++ plugins' own keyword tables read as text (LIGGGHTS' settings, LAMMPS 2021's keywords,
LAMMPS 2025's style names), the Python engines' defaults, the README's rows and each engine's
page, which must state that engine's defaults (the LAMMPS 2021 styles': stock's)."""
import ast
import dataclasses
import itertools
import re
from pathlib import Path

import pytest

from pyref.laws import OPTIONS as SCENE_OPTIONS, LawParams
from stickslip import law_options as lo
from stickslip.scene.model import Contact

ROOT = Path(__file__).resolve().parent.parent
STOCK_LIGGGHTS = Path("/usr/include/liggghts/tangential_model_history.h")
# settings the LIGGGHTS model registers as stock `tangential history` does (its energy
# bookkeeping): LIGGGHTS' own, not options of the law
LIGGGHTS_STOCK_SETTINGS = {"heating_tangential_history", "heating_tracking", "computeElasticPotential",
                           "computeDissipatedEnergy"}


def sources(folder, patterns=("*.h", "*.cpp")):
    """The text of a plugin's C++ files (every file below `folder`), comments dropped."""
    text = "\n".join(p.read_text() for pattern in patterns for p in sorted((ROOT / folder).rglob(pattern)))
    return re.sub(r"//[^\n]*|/\*.*?\*/", "", text, flags=re.S)


def ours(engine):
    """{option: spelling} of the options the engine's plugin parses (not fixed, not the host's)."""
    return {n: o.spellings[engine] for n, o in lo.OPTIONS.items()
            if o.spellings[engine].kind != "fixed" and not o.spellings[engine].host}


def other(option, value):
    return next(v for v in lo.OPTIONS[option].values if v != value)


# --- the table itself ----------------------------------------------------------------------------
def test_the_table_spells_every_option_on_every_engine():
    for name, o in lo.OPTIONS.items():
        assert set(o.spellings) == set(lo.ENGINES) and set(o.phrases) == set(o.values), name
        for engine, s in o.spellings.items():
            if s.kind in ("on_off", "suffix") or s.on:
                assert s.on in o.values and s.on != s.default, (name, engine)  # the words select the other value
            if s.kind != "fixed" and not s.host:
                assert s.default in o.values and len({s.say(v) for v in o.values}) == len(o.values), (name, engine)
    # the scene's options are pyref's, the law's default first
    assert {n: o.values for n, o in lo.OPTIONS.items() if n in SCENE_OPTIONS} == SCENE_OPTIONS


def test_a_fixed_option_refuses_another_value_and_an_unknown_one_is_named():
    assert lo.words("lammps_granular", lever_arm="radius") == []
    with pytest.raises(ValueError, match=r"lever_arm = 'contact': LAMMPS granular has radius only"):
        lo.words("lammps_granular", lever_arm="contact")
    with pytest.raises(ValueError, match=r"reset = 'half': must be one of spring, total"):
        lo.words("liggghts", reset="half")
    with pytest.raises(ValueError, match=r"friction: not an option of the law"):
        lo.arguments("yade", friction="on")


# --- the C++ plugins' own tables ---------------------------------------------------------------
def test_liggghts_settings_are_the_tables():
    """The model's on/off settings (registerOnOff, with their defaults) and the keywords it
    translates (their error lines name the values and the default)."""
    text = sources("liggghts_plugin", ("*.h",))
    on_off = {k: v == "true" for k, v in re.findall(r'registerOnOff\(\s*"(\w+)"\s*,\s*\w+\s*,\s*(true|false)\s*\)', text)}
    keywords = {k: (d, o) for k, d, o in re.findall(
        r'"(\w+) " \+ value \+ ": allowed values are (\w+) \(default\) and (\w+)"', text)}
    assert on_off and keywords
    table = ours("liggghts")
    for name, s in table.items():
        if s.kind == "on_off":
            assert on_off.get(s.key) == (s.default == s.on), (name, s.key, on_off.get(s.key))
        else:
            assert keywords.get(s.key) == (s.default, other(name, s.default)), (name, s.key, keywords.get(s.key))
    assert set(on_off) - LIGGGHTS_STOCK_SETTINGS == {s.key for s in table.values() if s.kind == "on_off"}
    assert set(keywords) == {s.key for s in table.values() if s.kind == "keyword"}
    checked = re.search(r"ON_OFF\[\]\s*=\s*\{(.*?)\}", text, re.S).group(1)  # (the values it checks first)
    assert set(re.findall(r'"(\w+)"', checked)) == set(on_off)
    if STOCK_LIGGGHTS.is_file():  # (the stock settings named above are stock's)
        assert set(re.findall(r'registerOnOff\(\s*"(\w+)"', STOCK_LIGGGHTS.read_text())) == LIGGGHTS_STOCK_SETTINGS


def test_lammps_2021_keywords_are_the_tables():
    """The styles' keyword table ({"keyword", "yes", "no", &Settings::flag} rows) and each
    flag's default in Settings; mu_k is a coefficient, not an option."""
    text = sources("lammps_plugin")
    rows = re.findall(r'\{\s*"(\w+)"\s*,\s*"(\w+)"\s*,\s*"(\w+)"\s*,\s*&Settings::(\w+)\s*\}', text)
    settings = re.search(r"struct\s+Settings\s*\{(.*?)\};", text, re.S).group(1)
    flags = dict(re.findall(r"bool\s+(\w+)\s*=\s*(true|false)\s*;", settings))
    got = {key: (yes if flags[flag] == "true" else no, {yes, no}) for key, yes, no, flag in rows}
    table = ours("lammps")
    assert got == {s.key: (s.default, set(lo.OPTIONS[n].values)) for n, s in table.items()}
    listed = re.search(r'keyword_list\(\)\s*\{\s*return\s*"([^"]*)"', text).group(1)
    assert sorted(listed.split(", ")) == sorted(["mu_k"] + [s.key for s in table.values()])


def granular_styles():
    """The style names the LAMMPS 2025 sub-model registers (its GranSubModStyle lines)."""
    text = sources("lammps_plugin/granular", ("*.h",))
    return set(re.findall(r"GranSubModStyle\(\s*([\w/]+)\s*,", text))


def test_lammps_2025_style_names_are_the_tables():
    """Every combination of the table's suffixes, in the table's order, and nothing else."""
    suffixes = [s.key for s in ours("lammps_granular").values()]
    assert suffixes == ["/total", "/exact", "/record"]
    want = {"stick_slip" + "".join(c) for k in range(len(suffixes) + 1) for c in itertools.combinations(suffixes, k)}
    assert granular_styles() == want


def test_the_granular_drivers_scripts_name_registered_styles():
    """The contract's LAMMPS 2025 batches (runnable only on that build) name, on each row's
    pair_coeff and wall line, the sub-model the table spells for the row, one LAMMPS registers."""
    from stickslip.contract import cases as lc, lammps as driver

    named = set()
    for key in {driver._lammps_key(c) for c in lc.CASES}:
        batch = [c for c in lc.CASES if driver._lammps_key(c) == key]
        lines = [ln for ln in driver._lammps_batch_script(batch, driver.GranularSubModel).splitlines()
                 if " tangential " in ln]
        rows = lines[1:] if batch[0].geometry == "pair" else lines  # (pair_coeff * * first)
        assert len(rows) == len(batch)
        for case, line in zip(batch, rows):
            name = line.split(" tangential ")[1].split()[0]
            assert name == lo.sub_model(reset=case.reset, slip_timing=case.timing, record="yes"), (case.name, line)
            named.add(name)
    assert named <= granular_styles() and len(named) >= 4


# --- the Python engines' defaults ----------------------------------------------------------------
def argument_defaults(path):
    """{function: {argument: default}} of the functions defined in a Python file."""
    out = {}
    for node in ast.walk(ast.parse(Path(path).read_text())):
        if isinstance(node, ast.FunctionDef):
            args = node.args.args[len(node.args.args) - len(node.args.defaults):]
            out[node.name] = {a.arg: ast.literal_eval(d) for a, d in zip(args, node.args.defaults)
                              if isinstance(d, ast.Constant)}
    return out


@pytest.mark.parametrize("engine, files", [("yade", sorted((ROOT / "yade_law/stickslip_yade").glob("*.py"))),
                                           ("deme", [ROOT / "deme_model/stickslip_deme.py"])])
def test_python_engines_defaults_are_the_tables(engine, files):
    spelt = {s.key: s.argument(s.default) for s in ours(engine).values()}
    seen = set()
    for path in files:
        for function, defaults in argument_defaults(path).items():
            for key in set(defaults) & set(spelt):
                if defaults[key] is None:  # (a checker's "not given")
                    continue
                assert defaults[key] == spelt[key], (path.name, function, key, defaults[key])
                seen.add(key)
    assert seen == set(spelt)


def test_pyref_and_the_scene_default_to_the_tables():
    for cls in (LawParams, Contact):
        defaults = {f.name: f.default for f in dataclasses.fields(cls)}
        for name, s in ours("pyref").items():
            assert defaults[s.key] == s.default, (cls.__name__, name)


# --- the pages ---------------------------------------------------------------------------------
def page(relative):
    return (ROOT / relative).read_text()


def section(text, title):
    """A page's section (## title) with its lines joined by single spaces."""
    body = text.split(f"\n## {title}\n", 1)[1].split("\n## ", 1)[0]
    return " ".join(body.split())


def test_the_readmes_option_rows_are_the_tables():
    rows = lo.readme_rows()
    lines = page("README.md").splitlines()
    assert rows[0] in lines, "README's option rows differ from `python -m stickslip.law_options`:\n" + "\n".join(rows)
    at = lines.index(rows[0])
    assert lines[at:at + len(rows)] == rows, "\n".join(rows)


DEFAULT_PAGES = {"liggghts": ["liggghts_plugin/doc/tangential_model_stick_slip.md"],
                 "lammps": ["lammps_plugin/doc/pair_gran_hooke_stickslip.md", "lammps_plugin/doc/fix_wall_gran_stickslip.md",
                            "lammps_plugin/doc/fix_wall_gran_region_stickslip.md"]}


@pytest.mark.parametrize("engine", sorted(DEFAULT_PAGES))
def test_each_c_plus_plus_styles_page_states_its_defaults(engine):
    """The Default section of each page names every option's default in the engine's words
    (the LAMMPS 2021 styles': stock's, `reset total`)."""
    for relative in DEFAULT_PAGES[engine]:
        text = section(page(relative), "Default")
        for name, s in ours(engine).items():
            assert f"`{s.say(s.default)}`" in text, (relative, name, s.say(s.default))


def test_lammps_2021_keyword_table_lists_the_values_default_first():
    text = page("lammps_plugin/doc/pair_gran_hooke_stickslip.md")
    for name, s in ours("lammps").items():
        assert f"| `{s.key}` | `{s.default}` or `{other(name, s.default)}` |" in text, name


def test_the_sub_models_page_states_its_defaults():
    """Without suffixes: each suffix option's default, in the table's words for it."""
    text = section(page("lammps_plugin/doc/gran_sub_mod_tangential_stick_slip.md"), "Default")
    assert text.startswith("Without suffixes:")
    for name, s in ours("lammps_granular").items():
        assert lo.OPTIONS[name].phrases[s.default] in text, name


def test_the_python_engines_pages_state_their_defaults():
    """YADE: every function heading of its API reference with an option shows its default;
    DEM-Engine: attach()'s defaults sentence; the scene file: its commented example."""
    yade = page("yade_law/README.md")
    headings = [ln for ln in yade.splitlines() if ln.startswith("### ") and "(" in ln]
    for name, s in ours("yade").items():
        with_it = [h for h in headings if f"{s.key}=" in h]
        assert with_it and all(s.say(s.default) in h for h in with_it), (name, with_it)
        assert f"| `{s.key}` | str | `\"{s.default}\"` |" in yade, name
    deme = next(ln for ln in page("deme_model/README.md").split("\n\n") if "`attach()`'s defaults:" in ln)
    for name, s in ours("deme").items():
        assert f"`{s.say(s.default)}`" in deme, name
    scene = page("docs/scene-format.md").splitlines()
    for name, s in ours("pyref").items():
        line = next(ln for ln in scene if ln.startswith(s.say(s.default)))
        assert "default" in line.split("#", 1)[1], (name, line)
