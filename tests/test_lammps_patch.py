# SPDX-License-Identifier: GPL-2.0-or-later
"""The sub-model as LAMMPS would merge it (tools/lammps_patch.py, tools/lammps_form.py): what
the patch adds reads like LAMMPS' own code; the patch is written for the tree it is given,
whichever way that tree registers sub-models and lays out its pages (each layout's files
written here by the tests; the clean LAMMPS 4 Jul 2026 tree too, where it was fetched); the
user's page (lammps_plugin/doc/) says what LAMMPS' page says; the example's committed logs
are what the example prints, on 1 and 4 processes, default and BIGBIG builds.

The 4 Jul 2026 tree, its builds and its clean source come from `./run.sh setup` with
STICKSLIP_SOURCE_BUILDS=lammps-2026 (BIGBIG: lammps-2026-bigbig; CI builds both); the tests
that need them skip without, and fail as root when the set-up was asked for them."""
import math
import os
import re
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

from conftest import as_root, lammps_release_launcher
from lammps_runs import MPI_ENV
from stickslip.adapters import lammps_granular, source_build_asked

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))

import lammps_form as lf  # noqa: E402
import lammps_patch as lp  # noqa: E402

GRANULAR = ROOT / "lammps_plugin" / "granular"
SUB_MODEL = sorted(GRANULAR.iterdir())
PAGE = ROOT / "lammps_plugin" / "doc" / "gran_sub_mod_tangential_stick_slip.md"
EXAMPLE = ROOT / "lammps_plugin" / "patch" / "examples" / "in.stick_slip"
TOP = ROOT / "build" / "lammps_2026"
KEYWORDS = [k for k, _ in lf.style_lines(lf.HEADER.read_text())]


def clean_source(tmp_path, paths):
    """`paths` of the clean 4 Jul 2026 tree, from Debian's source archive ./run.sh fetched."""
    lammps_release_launcher("lammps-2026")
    archive = next((TOP / "download").glob("lammps_*.orig.tar.*"))
    with tarfile.open(archive) as tar:
        for p in paths:
            target = tmp_path / p
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(tar.extractfile(tar.getmember(p)).read())
    return tmp_path


def lammps_form_files(with_style_lines):
    """{name: text} of the sub-model's C++ files as the patch adds them to a tree."""
    return {Path(path).name: lf.lammps_form(source, source.read_text(), with_style_lines)
            for path, source in lp.added().items() if path.startswith("src/")}


# ------------------------------------------------------------------ LAMMPS' form


@pytest.mark.parametrize("with_style_lines", [True, False], ids=["style header", "table"])
def test_what_the_patch_adds_reads_like_lammps_own(with_style_lines):
    """Each C++ file the patch adds: LAMMPS' banner, ASCII, lines of at most 100 characters,
    code in LAMMPS_NS::Granular_NS written as one namespace (as LAMMPS writes it), no macro
    defined in a header, no test of the host's release, no name of this repository or of
    another engine in its comments; the header's GranSubModStyle lines where the tree's build
    collects them and none for a tree with the table. The .cpp names its contributing authors
    and cites the paper as Developer_cite.rst says: a file-scope string whose first line
    gives the DOI, then the BibTeX entry, registered in the constructor when CiteMe is on."""
    files = lammps_form_files(with_style_lines)
    assert set(files) == {p.name for p in SUB_MODEL} | {"stick_slip_core.h"}
    for name, text in files.items():
        assert text.isascii(), name
        long = [i + 1 for i, line in enumerate(text.splitlines()) if len(line) > 100]
        assert not long, (name, long)
        assert "LAMMPS - Large-scale Atomic/Molecular Massively Parallel Simulator" in text.split("\n", 3)[1], name
        assert "This software is distributed under\n   the GNU General Public License." in text, name
        assert set(re.findall(r"\bnamespace\s+([\w:]+)\s*\{", text)) <= {"LAMMPS_NS::Granular_NS", ""}, name
        assert not re.search(r"^namespace (LAMMPS_NS|Granular_NS) \{", text, re.M), name
        if name.endswith(".h"):
            assert not re.search(r"^\s*#\s*define\s+(?!(LMP|GRAN_SUB_MOD)_\w*_H\b)", text, re.M), name
        for word in ("STICK_SLIP_ALWAYS", "STICK_SLIP_NOINLINE", "STICK_SLIP_UNLIKELY", "__builtin_expect",
                     "__attribute__", "stickslip::", "type_traits", "void_t", "HasSynchronizedVerlet",
                     "rescale_factor", "full_step_normal", "LIGGGHTS", "YADE", "2021", "2025", "docs/",
                     "law_core", "tools/"):
            assert word not in text, (name, word)
        assert ("GranSubModStyle(" in text) == (with_style_lines and name.endswith("stick_slip.h")), name
    cpp = files["gran_sub_mod_tangential_stick_slip.cpp"]
    assert "Contributing author" in cpp
    for member in ("gm->synchronized_verlet", "gm->nx_unrotated", "rotate_rescale_vec(", "allow_synchronization =",
                   "StickSlipCore::stock_ratio"):
        assert member in cpp, member
    cite = re.search(r'^static const char cite_stick_slip\[\] =\n((?:    ".*"\n)+?    ".*";)$', cpp, re.M)
    assert cite, "the citation string at file scope"
    first = cite[1].split("\n")[0]
    assert "doi:10.15587/2706-5448.2024.310428" in first and first.endswith('\\n\\n"')
    assert "@Article{" in cite[1] and "doi =" in cite[1]
    assert "if (lmp->citeme) lmp->citeme->add(cite_stick_slip);" in cpp
    core = files["stick_slip_core.h"]
    assert "namespace LAMMPS_NS::Granular_NS {" in core and "LMP_STICK_SLIP_CORE_H" in core


def test_the_lammps_form_is_one_source_transformed():
    """The repository keeps one source of each file: its LAMMPS form is made from it (a
    change of the source shows in the form), and a source that lost a text the form
    replaces stops the tool with one line naming it, instead of a form that keeps it."""
    core = lf.CORE.read_text()
    assert "StickSlipCore::kinetic" not in core and "static double kinetic(" in lf.core_form(core)
    assert "static double kinetic2(" in lf.core_form(core.replace("static double kinetic(", "static double kinetic2("))
    with pytest.raises(SystemExit, match=r"stick_slip_core.h has no 'namespace stickslip \{'"):
        lf.core_form(core.replace("namespace stickslip {", "namespace stick_slip {"))
    sub = lf.SUB_MODEL.read_text()
    with pytest.raises(SystemExit, match="full_step_normal"):
        lf.sub_model_form(sub.replace("full_step_normal(gm)", "full_step_normal(gm, 1)"))
    with pytest.raises(SystemExit, match="helpers that ask the release"):
        lf.sub_model_form(sub.replace("The host release.", "The release."))


@pytest.mark.parametrize("declaration, laid_out", [
    ("  static void f(double a,\n                double b)", "  static void f(double a, double b)"),
    ("  template <class R>\n  static double g(double *F, R r)", "  template <class R> static double g(double *F, R r)"),
    ("  static double h(" + ", ".join(f"double a{i}" for i in range(12)) + ")",
     "  static double h(double a0, double a1, double a2, double a3, double a4, double a5, double a6,\n"
     "                  double a7, double a8, double a9, double a10, double a11)"),
])
def test_a_declaration_without_its_macro_is_laid_out_as_clang_format_does(declaration, laid_out):
    assert lf.reflow(declaration) == laid_out


def test_clang_format_with_lammps_style():
    """clang-format with LAMMPS' src/.clang-format (from the 4 Jul 2026 tree) changes nothing:
    in the sub-model's files as they are copied, and in every C++ file as the patch adds it."""
    style = TOP / "source" / "src" / ".clang-format"
    if not style.is_file():
        lammps_release_launcher("lammps-2026")
        pytest.fail(f"{style} missing")
    if shutil.which("clang-format") is None:
        if as_root() and source_build_asked("lammps-2026"):
            pytest.fail("clang-format missing (./run.sh setup installs it with lammps-2026)")
        pytest.skip("clang-format missing")
    texts = {f.name: f.read_text() for f in SUB_MODEL if f.suffix in (".h", ".cpp")}
    for form in (True, False):
        texts.update({f"{n} (LAMMPS' form, {form})": t for n, t in lammps_form_files(form).items()})
    for name, text in texts.items():
        got = subprocess.run(["clang-format", f"--style=file:{style}", f"--assume-filename={name.split()[0]}"],
                             input=text, capture_output=True, text=True)
        assert got.returncode == 0 and got.stdout == text, f"clang-format would change {name}"


# ------------------------------------------------------------------ the tree's layout, written here

STOCK = ("linear_history", "mindlin")


def write_style_header_tree(top):
    """A tree whose build generates the style header: GranSubModStyle lines in the
    tangential header, and the tangential models on pair_granular.rst (one page)."""
    grains = top / "src" / "GRANULAR"
    grains.mkdir(parents=True)
    (grains / "gran_sub_mod_tangential.h").write_text(
        "#ifdef GRAN_SUB_MOD_CLASS\n// clang-format off\n"
        + "".join(f"GranSubModStyle({m},GranSubModTangential{m.title()},TANGENTIAL);\n" for m in STOCK)
        + "// clang-format on\n#else\n\n#ifndef GRAN_SUB_MOD_TANGENTIAL_H\n#define GRAN_SUB_MOD_TANGENTIAL_H\n"
        + STUB_CLASSES + "#endif\n#endif\n")
    items = "".join(f"{i}. *{m}* : :math:`k_t`, :math:`x_{{\\gamma,t}}`, :math:`\\mu_s`\n" for i, m in enumerate(STOCK, 1))
    write_pages(top, PAGE_HEAD + "Tangential models\n\n" + items + "\nMore about them.\n\n"
                + "The *mindlin_rescale/force* option rescales the force.\n\n----------\n\n" + PAGE_TAIL)


def write_table_tree(top):
    """A tree with the checked-in table of sub-models (an #include of each header, a row
    { "keyword", &creator<Class>, TYPE } each) and split pages: the list on
    pair_granular.rst links to the sections of granular_tangential_models.rst."""
    grains = top / "src" / "GRANULAR"
    grains.mkdir(parents=True)
    rows = "".join(f'  {{ "{m}",{" " * (16 - len(m))}&creator<GranSubModTangential{m.title()}>, TANGENTIAL }},\n'
                   for m in STOCK)
    (grains / "gran_sub_mod_register.cpp").write_text(
        '// the table of sub-models\n#include "gran_sub_mod.h"\n#include "granular_model.h"\n\n'
        '#include "gran_sub_mod_normal.h"\n#include "gran_sub_mod_tangential.h"\n#include "gran_sub_mod_twisting.h"\n\n'
        "namespace LAMMPS_NS::Granular_NS {\n\n"
        "template <typename T> static GranSubMod *creator(GranularModel *gm, LAMMPS *lmp)\n{\n"
        "  return new T(gm, lmp);\n}\n\n// clang-format off\nconst GranSubModInfo gran_sub_mod_table[] = {\n"
        '  { "hooke",          &creator<GranSubModNormalHooke>,          NORMAL },\n' + rows
        + '  { "marshall",       &creator<GranSubModTwistingMarshall>,     TWISTING }\n};\n// clang-format on\n\n'
        "}    // namespace LAMMPS_NS::Granular_NS\n")
    (grains / "gran_sub_mod_tangential.h").write_text(
        "#ifndef GRAN_SUB_MOD_TANGENTIAL_H\n#define GRAN_SUB_MOD_TANGENTIAL_H\n" + STUB_CLASSES + "#endif\n")
    items = "".join(f"{i}. :ref:`{m} <{m}_tangential_model>` : :math:`k_t`, :math:`x_{{\\gamma,t}}`, "
                    f":math:`\\mu_t`\n" for i, m in enumerate(STOCK, 1))
    write_pages(top, PAGE_HEAD + ":doc:`Tangential models <granular_tangential_models>`\n\n" + items + "\n----------\n\n"
                + PAGE_TAIL)
    sections = "".join(f".. _{m}_tangential_model:\n\n*{m}* tangential model\n{'-' * (len(m) + 19)}\n\n"
                       f"The *{m}* model.\n\n" for m in STOCK)
    (top / lp.TANGENTIAL_PAGE).write_text("Models for tangential friction\n==============================\n\n" + sections
                                          + 'References\n""""""""""\n\n.. _Mindlin1949:\n\n**(Mindlin, 1949)** A paper.\n')


# the base classes the sub-model's header and the table need (declarations)
STUB_CLASSES = """
namespace LAMMPS_NS {
class LAMMPS;
namespace Granular_NS {
  enum SubModelType { NORMAL, DAMPING, TANGENTIAL, ROLLING, TWISTING, HEAT };
  class GranularModel;
  class GranSubMod {
   public:
    GranSubMod(GranularModel *, LAMMPS *);
    virtual ~GranSubMod() = default;
    virtual void coeffs_to_local() {}
    virtual void mix_coeffs(double *, double *) {}
  };
  class GranSubModTangential : public GranSubMod {
   public:
    GranSubModTangential(GranularModel *gm, LAMMPS *lmp) : GranSubMod(gm, lmp) {}
    virtual void calculate_forces() = 0;
  };
  class GranSubModTangentialLinear_History : public GranSubModTangential {
   public:
    GranSubModTangentialLinear_History(GranularModel *, LAMMPS *);
    void calculate_forces() override;
  };
  class GranSubModTangentialMindlin : public GranSubModTangentialLinear_History {
   public:
    GranSubModTangentialMindlin(GranularModel *, LAMMPS *);
  };
}
}
"""
STUBS = {
    "gran_sub_mod.h": "#pragma once\n#include \"gran_sub_mod_tangential.h\"\nnamespace LAMMPS_NS::Granular_NS {\n"
                      "struct GranSubModInfo { const char *name; GranSubMod *(*creator)(GranularModel *, LAMMPS *); "
                      "int type; };\n}\n",
    "granular_model.h": "#pragma once\n",
    "gran_sub_mod_normal.h": "#pragma once\n#include \"gran_sub_mod.h\"\nnamespace LAMMPS_NS::Granular_NS {\n"
                             "class GranSubModNormalHooke : public GranSubMod {\n public:\n"
                             "  GranSubModNormalHooke(GranularModel *, LAMMPS *);\n};\n}\n",
    "gran_sub_mod_twisting.h": "#pragma once\n#include \"gran_sub_mod.h\"\nnamespace LAMMPS_NS::Granular_NS {\n"
                               "class GranSubModTwistingMarshall : public GranSubMod {\n public:\n"
                               "  GranSubModTwistingMarshall(GranularModel *, LAMMPS *);\n};\n}\n",
}
PAGE_HEAD = "pair_style granular command\n===========================\n\n"
PAGE_TAIL = ("These extra quantities can be accessed by the :doc:`compute pair/local\n<compute_pair_local>` command, "
             "as *p1*, *p2*, ..., *p12*\\ .\n\nRestrictions\n\"\"\"\"\"\"\"\"\"\"\"\"\n\nThis pair style requires "
             "you to use the :doc:`comm_modify vel yes\n<comm_modify>` command so that velocities are stored by ghost "
             "atoms.\n\nReferences\n\"\"\"\"\"\"\"\"\"\"\n\n.. _Vyas2025:\n\n**(Vyas et al, 2025)** A paper.\n")


def write_pages(top, page):
    (top / "doc" / "src").mkdir(parents=True)
    (top / lp.PAGE).write_text(page)
    (top / lp.SPELLING).parent.mkdir(parents=True)
    (top / lp.SPELLING).write_text("hdnnp\nrunner\nRUNNER\nHearn\nheat\nij\nJiang\nKfoury\nKhersonskii\nManby\nmanybody\n")


def applied(tree, tmp_path):
    """The tree after `patch -p1` of the tool's patch (git apply --check first)."""
    patch = tmp_path / "stick_slip.patch"
    patch.write_text(lp.patch(tree))
    for cmd in (["git", "apply", "--check", str(patch)], ["patch", "-p1", "-s", "-i", str(patch)]):
        got = subprocess.run(cmd, cwd=tree, capture_output=True, text=True)
        assert got.returncode == 0, (cmd, got.stdout, got.stderr)
    return tree


def compiles(tree, source, tmp_path):
    """Whether g++ compiles `source` (C++17, LAMMPS' standard) against the tree's
    src/GRANULAR/ and the stub headers."""
    stubs = tmp_path / "stubs"
    stubs.mkdir(exist_ok=True)
    for name, text in STUBS.items():
        if not (tree / "src" / "GRANULAR" / name).exists():
            (stubs / name).write_text(text)
    got = subprocess.run(["g++", "-std=c++17", "-Wall", "-Werror", "-fsyntax-only", "-I", str(tree / "src" / "GRANULAR"),
                          "-I", str(stubs), "-x", "c++", "-"], input=source, capture_output=True, text=True)
    assert got.returncode == 0, got.stderr[-3000:]


@pytest.mark.parametrize("write, layout", [(write_style_header_tree, ("style header", "one page")),
                                           (write_table_tree, ("table", "split"))],
                         ids=["style header, one page", "table, split pages"])
def test_the_patch_registers_the_keyword_in_either_layout(tmp_path, write, layout):
    """The tool finds the tree's layout and the applied patch registers every keyword: with
    a generated style header, GranSubModStyle lines that LAMMPS' style scan collects (the
    scan's header, included as LAMMPS' factory includes it, compiles); with the table, an
    #include of the sub-model's header in the includes' order and a row per keyword, which
    compiles against that header's classes, and no GranSubModStyle line left (dead there)."""
    tree = tmp_path / "lammps"
    write(tree)
    assert lp.layout(tree) == layout
    assert lp.main([str(tree), "--layout"]) == 0
    applied(tree, tmp_path)
    grains = tree / "src" / "GRANULAR"
    header = (grains / lf.HEADER.name).read_text()
    if layout[0] == "style header":
        # LAMMPS' style scan: every header of the folder with a GranSubModStyle line, included with
        # GRAN_SUB_MOD_CLASS defined and GranSubModStyle expanding to what the factory needs
        scanned = sorted(h.name for h in grains.glob("*.h") if "GranSubModStyle(" in h.read_text())
        assert lf.HEADER.name in scanned
        entries = re.findall(r"GranSubModStyle\(([^,]+),(\w+),(\w+)\);", "".join((grains / h).read_text() for h in scanned))
        assert [k for k, _, _ in entries if k.startswith("stick_slip")] == KEYWORDS
        style_header = "".join(f'#include "{h}"\n' for h in scanned)  # (as the build writes it)
        source = ('#include "gran_sub_mod.h"\n' + style_header + "using namespace LAMMPS_NS;\n"
                  "using namespace Granular_NS;\n"
                  "template <class T> GranSubMod *make(GranularModel *gm, LAMMPS *lmp) { return new T(gm, lmp); }\n"
                  "#define GRAN_SUB_MOD_CLASS\n#define GranSubModStyle(key, Class, type) "
                  "GranSubModInfo entry_##Class{#key, &make<Class>, type};\n" + style_header)
        compiles(tree, source, tmp_path)
    else:
        table = (grains / "gran_sub_mod_register.cpp").read_text()
        rows = re.findall(r'\{ "([^"]+)",\s*&creator<(\w+)>,\s*(\w+) \}', table)
        assert [k for k, _, t in rows if k.startswith("stick_slip") and t == "TANGENTIAL"] == KEYWORDS
        assert rows[-1][0] == "marshall" and table.count("&creator<") == len(STOCK) + 2 + len(KEYWORDS)
        includes = re.findall(r'#include "(gran_sub_mod_\w+\.h)"', table)
        assert lf.HEADER.name in includes and includes[1:] == sorted(includes[1:]), includes
        assert "GranSubModStyle" not in header
        compiles(tree, table, tmp_path)


@pytest.mark.parametrize("write", [write_style_header_tree, write_table_tree], ids=["one page", "split pages"])
def test_the_documentation_goes_where_the_pages_keep_it(tmp_path, write):
    """One page: the list's next item (*stick_slip*), the description before the section's
    rule, the reference last. Split pages: the list's next item links to the model's section
    (:ref:), the section (label, title) before the tangential page's References, the
    reference at its end. Both: the single() values and the restriction where pair_granular.rst
    has them, each passage once; the spelling list keeps its order around the authors' names."""
    tree = tmp_path / "lammps"
    write(tree)
    split = lp.pages(tree) == "split"
    applied(tree, tmp_path)
    page = (tree / lp.PAGE).read_text()
    lines = page.splitlines()
    last = max(i for i, x in enumerate(lines) if x.startswith(f"{len(STOCK)}. "))
    item = lines[last + 1]
    assert item.startswith(f"{len(STOCK) + 1}. " + (f":ref:`stick_slip <{lp.LABEL}>`" if split else "*stick_slip*"))
    assert item.endswith(lp._fragment("item").strip())
    models = (tree / lp.TANGENTIAL_PAGE).read_text() if split else page
    model, reference = lp._fragment("model"), lp._fragment("reference")
    assert models.count(model) == 1 and models.rstrip().endswith(reference.rstrip())
    if split:
        assert f".. _{lp.LABEL}:\n\n*stick_slip* tangential model\n" in models
        assert models.index(model) < models.index("References") and model not in page
    else:
        assert page.index("The *mindlin_rescale/force* option") < page.index(model) < page.index("\n----------\n",
                                                                                                page.index(model))
    for name in ("single", "restrictions"):
        assert page.count(lp._fragment(name)) == 1, name
    assert page.index(lp._fragment("single")) < page.index("Restrictions") < page.index(lp._fragment("restrictions"))
    words = (tree / lp.SPELLING).read_text().splitlines()
    assert words == ["hdnnp", "runner", "RUNNER", "Hearn", "heat", "ij", "Jiang", "Kfoury", "Khellaf", "Khersonskii",
                     "Manby", "Mansouri", "manybody"]


def test_the_spelling_list_takes_a_name_where_its_order_puts_it():
    """Where the list's order is broken near a place (a word out of its place before it), the
    name still goes between its neighbours in the order, not after the first later word."""
    words = ["hbond", "hdnnp", "runner", "RUNNER", "Hearn", "Kelkar", "Kfoury", "Khersonskii", "Ki"]
    assert lp.spelling_place(words, "Khellaf") == words.index("Khersonskii")
    assert lp.spelling_place(words, "aaa") == 0 and lp.spelling_place(words, "zzz") == len(words)


@pytest.mark.parametrize("make, looked_for", [
    (lambda t: None, "looked for src/GRANULAR/gran_sub_mod_register.cpp (a table of sub-models) and for "
                     "GranSubModStyle lines in src/GRANULAR/gran_sub_mod_tangential.h"),
    (lambda t: (t / "src/GRANULAR").mkdir(parents=True) or (t / lp.REGISTER).write_text("// no table\n"),
     "no row { \"keyword\", &creator<Class>, TANGENTIAL } in its table"),
    (lambda t: (t / "src/GRANULAR").mkdir(parents=True) or (t / lp.STYLE_SOURCE).write_text("GranSubModStyle(a,B,TANGENTIAL);\n"),
     "no doc/src/pair_granular.rst: looked for it"),
])
def test_a_tree_it_does_not_recognise_stops_it_with_one_line(tmp_path, capsys, make, looked_for):
    """A tree with no way of registering sub-models that the tool knows, or no page: one line
    on stderr saying what it looked for, exit 2 (a bad argument), and no patch."""
    make(tmp_path)
    assert lp.main([str(tmp_path), "-o", str(tmp_path / "out.patch")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("lammps_patch: ") and looked_for in err, err
    assert not (tmp_path / "out.patch").exists()


def test_a_page_that_lost_a_place_is_refused(tmp_path):
    """A tree whose page has lost a place the patch needs: one line naming the page and the
    place, not a patch that would not apply."""
    write_style_header_tree(tmp_path)
    (tmp_path / lp.PAGE).write_text((tmp_path / lp.PAGE).read_text().replace("as *p1*", "as *q1*"))
    with pytest.raises(SystemExit, match=r"pair_granular.rst: the place of the single\(\) values .* found 0 times"):
        lp.patch(tmp_path)


def test_the_patch_applies_to_the_clean_4_jul_2026_tree(tmp_path):
    """LAMMPS 4 Jul 2026 (Debian's source archive): a generated style header and one page;
    the patch applies (git apply --check, patch), item 7 follows item 6, the description
    closes the tangential section, the reference is last, ASCII only."""
    tree = clean_source(tmp_path / "lammps", [lp.PAGE, lp.SPELLING, lp.STYLE_SOURCE])
    assert lp.layout(tree) == ("style header", "one page")
    assert lp.reads(tree) == [lp.PAGE, lp.SPELLING, lp.STYLE_SOURCE]
    page = (applied(tree, tmp_path) / lp.PAGE).read_text()
    assert page.isascii()
    lines = page.splitlines()
    six = next(i for i, x in enumerate(lines) if x.startswith("6. *mindlin_rescale/force*"))
    assert lines[six + 1].startswith("7. *stick_slip*")
    assert page.rstrip().endswith("https://doi.org/10.15587/2706-5448.2024.310428")
    model = page.index("For *tangential stick_slip*")
    assert page.index("The *mindlin_rescale/force* option") < model < page.index("\n----------\n", model)
    words = (tree / lp.SPELLING).read_text().splitlines()
    for w in lp.SPELLING_WORDS:
        i = words.index(w)
        assert words[i - 1].lower() <= w.lower() <= words[i + 1].lower(), w


# ------------------------------------------------------------------ the pull request's description


@pytest.mark.parametrize("write, registration", [(write_style_header_tree, "GranSubModStyle lines"),
                                                 (write_table_tree, "gran_sub_mod_register.cpp's table")],
                         ids=["style header", "table"])
def test_the_pull_requests_description_is_the_tools(tmp_path, write, registration):
    """tools/lammps_pr.py: LAMMPS' new-feature sections in order; the authors (and the LGPL
    answer) left to the submitter; the comparison with linear_history/static in the page's
    own three sentences; implementation notes that state the tree's registration and answer
    each point of the review; the tests (their commands, not run without a build); the
    post-submission checklist unticked."""
    import lammps_pr

    write(tmp_path)
    text = lammps_pr.description(tmp_path)
    heads = ["**Summary**", "**Related Issues**", "**Author(s)**", "**Licensing**", "**Backward Compatibility**",
             "**Beside linear_history/static**", "**Implementation Notes**", "**Tests run**",
             "## Post Submission Checklist", "## Further Information, Files, and Links"]
    at = [text.index(h) for h in heads]
    assert at == sorted(at)
    section = lambda h: text[text.index(h):min([i for i in at if i > text.index(h)] + [len(text)])]  # noqa: E731
    assert lammps_pr.LEFT in section("**Author(s)**") and lammps_pr.LEFT in section("**Licensing**")
    page = PAGE.read_text()
    said = page[page.index("## Beside linear_history/static"):page.index("## Mixing")].strip().split("\n\n")[-1]
    assert said.replace("\n", " ") in section("**Beside linear_history/static**")
    notes = section("**Implementation Notes**")
    assert registration in notes
    for point in ("versionadded:: TBD", "mu_{t,s}", "time steps in which the contact slipped", "Developer_cite.rst",
                  "STICK_MARGIN", "define no macro", "LAMMPS_NS::Granular_NS", "synchronized_verlet",
                  "atom_style full", "date_generated", "in.granular_stick_slip", "2 by 2 by 1",
                  "false_positives.txt"):
        assert point in notes, point
    assert "(not run for this description)" in section("**Tests run**")
    boxes = re.findall(r"^- \[ \] .+$", section("## Post Submission Checklist"), re.M)
    assert len(boxes) == len(lammps_pr.CHECKLIST) == 10
    (tmp_path / "empty").mkdir()
    assert lammps_pr.main([str(tmp_path / "empty"), "-o", str(tmp_path / "pr.md")]) == 2
    assert not (tmp_path / "pr.md").exists()


# ------------------------------------------------------------------ the two pages agree


def test_the_user_page_says_what_lammps_page_says():
    """The names, the coefficients' ranges (as the C++ refuses them), the default, the DOI,
    the restrictions and the tested releases: on the user's page as on LAMMPS' page (the
    patch's passages, in LAMMPS' notation mu_{t,s}, mu_{t,k}) and in the code; the page marks
    the new model for the next release and claims no last bit."""
    md = PAGE.read_text()
    rst = "".join(lp._fragment(n) for n in ("item", "model", "single", "restrictions", "reference"))
    cpp = lf.SUB_MODEL.read_text()
    assert all(f"`{n}`" in md for n in KEYWORDS) and len(KEYWORDS) == 8
    assert all(f"/{o}" in rst for o in ("total", "exact", "record"))
    for rule_md, rule_rst, rule_cpp in (("μs/2 ≤ mu_k ≤ μs", r"\mu_{t,s}/2 \le \mu_{t,k} \le \mu_{t,s}", "[mu_s/2, mu_s]"),
                                        ("`mu_s` = static friction coefficient μs, > 0", r"\mu_{t,s}", "mu_s = {} is outside its allowed range: > 0"),
                                        ("≥ 0: the tangential dashpot", "x_{\\gamma,t}", "x_gamma,t = {} is outside its allowed range: >= 0"),
                                        ("stiffness (force/distance units), > 0; or `NULL`", "NULL", "> 0, or NULL")):
        assert rule_md in md and rule_rst in rst and rule_cpp in cpp, rule_md
    assert not re.search(r"\\mu_[sk]\b", rst), "LAMMPS' page writes mu_{t,s} and mu_{t,k}"
    assert rst.startswith(lp._fragment("item")) and lp._fragment("model").startswith(".. versionadded:: TBD\n\n")
    assert "last bit" not in rst + md
    assert "number of time steps in which the contact slipped" in lp._fragment("single")
    doi = "10.15587/2706-5448.2024.310428"
    assert doi in md and doi in rst and doi in cpp
    for restriction in ("atom_style sphere", "comm_modify vel yes", "synchronized_verlet"):
        assert restriction in md, restriction
    assert "synchronized_verlet" in rst and "allow_synchronization" in cpp
    tested = [v for v, _ in lammps_granular.RELEASES.values()]
    assert f"Tested releases: **{tested[0]}** and **{tested[1]}**." in md
    readme = (ROOT / "README.md").read_text()
    assert all(v in readme for v in tested) and "2Aug2023" not in readme + md


# ------------------------------------------------------------------ the example


def thermo(text):
    """The thermo table of a LAMMPS log or screen output: its header line to 'Loop time'."""
    start = text.index("\n   Step ")
    return text[start:text.index("\nLoop time", start)]


def rows(text):
    return [[float(v) for v in line.split()] for line in thermo(text).splitlines()[2:]]


def committed_log(n):
    return (EXAMPLE.parent / f"log.{lp.LOG_DATE}.stick_slip.g++.{n}").read_text()


@pytest.mark.parametrize("build", ["build", "bigbig"])
def test_the_examples_logs_are_its_runs(tmp_path, build):
    """examples/granular/in.stick_slip on 1 and 4 processes prints the thermo table of its
    committed logs (log.4Jul26.stick_slip.g++.1 and .4), on the default build and on the
    BIGBIG one."""
    lmp = lammps_release_launcher("lammps-2026")
    exe = TOP / build / "lmp" if build == "bigbig" else lmp
    if not exe.is_file():
        if as_root() and source_build_asked("lammps-2026-bigbig"):
            pytest.fail(f"{exe} missing")
        pytest.skip(f"engine missing: lammps_granular: {exe} missing (STICKSLIP_SOURCE_BUILDS=lammps-2026-bigbig)")
    for n in (1, 4):
        cmd = [str(exe), "-in", str(EXAMPLE), "-log", "none", "-echo", "screen", "-nocite"]
        if n > 1:
            cmd = ["mpirun", "-np", str(n), "--oversubscribe"] + cmd
        got = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, env=dict(os.environ, **MPI_ENV))
        assert got.returncode == 0, got.stdout[-2000:] + got.stderr[-2000:]
        assert thermo(got.stdout) == thermo(committed_log(n)), n


def test_the_examples_logs_show_four_processes_sharing_the_bed():
    """The 4-process log is the bed split over a 2 by 2 by 1 grid of processes (each owns
    part of the 320 grains and sees others as ghosts), where the 1-process log has one owner
    of all; the physics is the same: the two thermo tables agree to their printed digits
    (the runs differ by the order in which forces are summed, round-off that this settled,
    dissipative bed does not grow to 8 digits) and the slip counts exactly. On both, the
    floor's friction ratio follows tan(tilt) while the bed sticks (tilt <= 20 degrees,
    tan <= 0.36 < mu_k; within twice what the bed's vibration gives the settled, untilted
    bed), never exceeds mu_s = 0.5 (no contact's |F_t| does), and the bed slides at the end
    (the floor's contacts slip in over a thousand more steps, its kinetic energy rises a
    hundredfold)."""
    one, four = committed_log(1), committed_log(4)
    assert "1 by 1 by 1 MPI processor grid" in one and "2 by 2 by 1 MPI processor grid" in four
    owned = re.search(r"Nlocal:\s+(\S+) ave\s+(\S+) max\s+(\S+) min", four)
    assert float(owned[1]) == 80 and float(owned[2]) < 320 and "with 320 atoms" in four
    assert re.search(r"Nlocal:\s+320 ave\s+320 max\s+320 min", one)
    assert "CITE-CITE" in one and "tangential stick_slip: doi:10.15587/2706-5448.2024.310428" in one
    a, b = rows(one), rows(four)
    assert len(a) == len(b) == 13
    for r, s in zip(a, b):
        assert r[0] == s[0] and r[3] == s[3]
        for x, y in zip(r[1:3] + r[4:], s[1:3] + s[4:]):
            assert abs(x - y) <= 1e-7 * abs(x) + 1e-300, (r, s)
    # at rest the floor's friction balances the tilted weight exactly, ratio = tan(tilt); the
    # bed's vibration adds its acceleration over g, which the settled rows with no tilt show
    shake = max(abs(ratio) for step, tilt, _, _, ratio in a if tilt == 0 and step >= 1500)
    assert 0 < shake < 0.02
    for step, tilt, ke, slips, ratio in a:
        assert ratio <= 0.5
        if 0 < tilt <= 20:
            assert abs(ratio - math.tan(math.radians(tilt))) <= 2 * shake, (step, tilt, ratio, shake)
    assert a[-1][3] - a[-5][3] >= 1000 and a[-1][2] > 100 * a[-5][2]


@pytest.mark.long
def test_the_documentation_builds_without_a_new_warning():
    """tools/lammps_docs.py on the patched 4 Jul 2026 tree: LAMMPS' Sphinx configuration
    builds pair_granular.rst (html and spelling) with no warning and no misspelt word that
    the unpatched page lacks, ASCII only, roles as LAMMPS writes them (the tool's docstring)."""
    lammps_release_launcher("lammps-2026")
    import lammps_docs

    venv = lammps_docs.VENV
    if not (venv / "bin" / "python").is_file():
        pytest.fail(f"{venv} missing (./run.sh setup makes it with lammps-2026)")
    lines, ok = lammps_docs.check(TOP / "source", TOP / "pristine", venv)
    print("\n".join(lines))
    assert ok, "\n".join(lines)
