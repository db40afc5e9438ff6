# SPDX-License-Identifier: GPL-2.0-or-later
"""What a user needs to adopt a release: the license (LICENSE, pyproject.toml, an SPDX line in
every source file), the citation (CITATION.cff, valid against its schema), and one version
everywhere, pyproject.toml's: the command line, summary.json, the YADE law, the DEM-Engine
model, the C++ plugins' header and the start-up line of both launchers.
"""
import importlib.util
import json
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from conftest import skip_engine
from stickslip.adapters.lammps_family import serial_mpi_env

ROOT = Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
VERSION = PYPROJECT["project"]["version"]
LICENSE = "GPL-2.0-or-later"


def load_spdx_tool():
    spec = importlib.util.spec_from_file_location("spdx", ROOT / "tools" / "spdx.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


spdx = load_spdx_tool()


# --- license ---------------------------------------------------------------------------------

def test_the_license_is_the_gpl_2_text_and_pyproject_and_the_citation_name_it():
    text = (ROOT / "LICENSE").read_text()
    assert text.split()[:7] == ["GNU", "GENERAL", "PUBLIC", "LICENSE", "Version", "2,", "June"]
    assert "END OF TERMS AND CONDITIONS" in text and "any later version" in text
    assert PYPROJECT["project"]["license"] == LICENSE and PYPROJECT["project"]["license-files"] == ["LICENSE"]
    assert re.search(rf"^license: {re.escape(LICENSE)}$", (ROOT / "CITATION.cff").read_text(), re.M)
    assert spdx.TAG == f"SPDX-License-Identifier: {LICENSE}"


def test_every_tracked_source_file_carries_the_spdx_line():
    files = spdx.tracked_sources()
    assert len(files) > 150 and "run.sh" in files and ".ci/run" in files
    assert {f.rsplit(".", 1)[-1] for f in files} >= {"py", "sh", "cpp", "h", "cu", "txt"}
    missing = [f for f in files if not spdx.has_tag((ROOT / f).read_text(), f)]
    assert not missing, f"no SPDX line (add it: .venv/bin/python tools/spdx.py): {missing}"
    lammps_form = [f for f in files if f.startswith(spdx.LAMMPS_FORM)]
    assert lammps_form and not any(spdx.has_tag((ROOT / f).read_text()) for f in lammps_form), \
        "the sub-model's files carry LAMMPS' banner in LAMMPS' form, not the SPDX line"


@pytest.mark.parametrize("name, text, first_lines", [
    ("x.py", '#!/usr/bin/env python3\n# -*- coding: utf-8 -*-\n"""Doc."""\n',
     ["#!/usr/bin/env python3", "# -*- coding: utf-8 -*-", f"# {spdx.TAG}", '"""Doc."""']),
    ("x.py", '"""Doc."""\nimport os\n', [f"# {spdx.TAG}", '"""Doc."""']),
    (".ci/run", "#!/usr/bin/env bash\nset -e\n", ["#!/usr/bin/env bash", f"# {spdx.TAG}", "set -e"]),
    ("a/CMakeLists.txt", "# Builds it\nproject(x)\n", [f"# {spdx.TAG}", "# Builds it"]),
    ("x.cpp", "/* Registers x\n   and y. */\n#include <x>\n", [f"/* {spdx.TAG}", "   Registers x", "   and y. */"]),
    ("x.h", "/* -*- c++ -*- ---\n   x\n--- */\n", ["/* -*- c++ -*- ---", f"   {spdx.TAG}", "   x"]),
    ("x.cu", "// the law\n", [f"// {spdx.TAG}", "// the law"]),
    ("x.h", "#pragma once\n", [f"// {spdx.TAG}", "#pragma once"]),
])
def test_the_spdx_line_goes_where_the_engines_put_it(name, text, first_lines):
    assert not spdx.has_tag(text) and spdx.is_source(name)
    out = spdx.with_tag(name, text)
    assert out.splitlines()[:len(first_lines)] == first_lines and spdx.has_tag(out)
    assert out.endswith(text.splitlines(keepends=True)[-1])
    assert spdx.with_tag(name, text) == out and not spdx.is_source("README.md")


def test_the_spdx_tool_adds_the_line_once(tmp_path, monkeypatch):
    monkeypatch.setattr(spdx, "ROOT", tmp_path)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a.py").write_text('"""Doc."""\n')
    spdx.main(["a.py"])
    spdx.main(["a.py"])
    assert (tmp_path / "a.py").read_text() == f'# {spdx.TAG}\n"""Doc."""\n'


# --- citation ----------------------------------------------------------------------------------

def test_the_citation_is_valid_cff_and_cites_the_software_and_the_paper():
    from cffconvert.cli.create_citation import create_citation

    citation = create_citation(str(ROOT / "CITATION.cff"), None)
    citation.validate()  # raises when the file breaks CFF 1.2.0's schema
    cff = citation.cffobj
    assert cff["cff-version"] == "1.2.0" and cff["type"] == "software"
    assert cff["version"] == VERSION and cff["license"] == LICENSE
    paper = [r for r in cff["references"] if r.get("doi") == "10.15587/2706-5448.2024.310428"]
    assert len(paper) == 1 and [a["family-names"] for a in paper[0]["authors"]] == ["Khellaf", "Mansouri"]
    assert (paper[0]["year"], paper[0]["volume"], paper[0]["issue"], paper[0]["start"], paper[0]["end"]) == \
        (2024, 4, "1(78)", 17, 25)


def release_dates(changelog):
    """{version: date} of CHANGELOG.md's release headings ("## [1.0.0] - 2026-11-28"); a
    release heading without its date maps to None."""
    return {m.group(1): m.group(2) for m in re.finditer(r"^## \[(\d+\.\d+\.\d+)\](?: - (\d{4}-\d\d-\d\d))?$",
                                                         changelog, re.M)}


def test_every_release_carries_its_date_and_the_citation_that_of_its_version():
    """Each release in CHANGELOG.md is dated, and CITATION.cff's date-released is the date of
    the version it cites."""
    from cffconvert.cli.create_citation import create_citation

    dates = release_dates((ROOT / "CHANGELOG.md").read_text())
    assert dates and all(dates.values()), dates
    assert release_dates("## [1.0.0]\n## [0.9.0] - 2026-01-02\n") == {"1.0.0": None, "0.9.0": "2026-01-02"}
    cff = create_citation(str(ROOT / "CITATION.cff"), None).cffobj
    assert str(cff["date-released"]) == dates[cff["version"]]


def test_the_citation_validation_fails_on_a_broken_file(tmp_path):
    from cffconvert.cli.create_citation import create_citation

    broken = tmp_path / "CITATION.cff"
    text = (ROOT / "CITATION.cff").read_text()
    broken.write_text(text.replace("cff-version: 1.2.0\n", "cff-version: 1.2.0\nlicence: x\n"))
    with pytest.raises(Exception):
        create_citation(str(broken), None).validate()


# --- one version ---------------------------------------------------------------------------------

def python_says(*code):
    return subprocess.run([sys.executable, "-c", "; ".join(code)], cwd=ROOT, capture_output=True, text=True,
                          check=True).stdout.strip()


def test_one_version_in_pyproject_the_package_the_laws_the_header_citation_and_changelog():
    import stickslip
    from stickslip.adapters import deme

    assert re.fullmatch(r"\d+\.\d+\.\d+", VERSION)
    assert stickslip.__version__ == VERSION
    assert deme.helper().__version__ == VERSION
    assert python_says("import sys", "sys.path.insert(0, 'yade_law')", "import stickslip_yade",
                       "print(stickslip_yade.__version__)") == VERSION
    header = (ROOT / "lammps_plugin" / "stickslip_version.h").read_text()
    assert re.findall(r'^#define STICKSLIP_VERSION "(.*)"$', header, re.M) == [VERSION]
    assert f"## [{VERSION}]" in (ROOT / "CHANGELOG.md").read_text()


def test_the_command_line_and_summary_json_give_the_version(tmp_path):
    cli = Path(sys.executable).parent / "stickslip"
    got = subprocess.run([str(cli), "--version"], capture_output=True, text=True)
    assert got.returncode == 0 and got.stdout == f"stickslip {VERSION}\n"
    run = subprocess.run([str(cli), "run", "drag", "--duration", "0.001", "--quiet", "--out", str(tmp_path)],
                         capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert json.loads((tmp_path / "summary.json").read_text())["version"] == VERSION


@pytest.mark.parametrize("engine", ["liggghts", "lammps"])
def test_each_plugin_launcher_prints_the_version_once_at_start(engine, tmp_path):
    from stickslip import adapters

    skip_engine(engine)
    (tmp_path / "in.empty").write_text("\n")
    proc = subprocess.run([str(adapters.get(engine).LAUNCHER), "-in", "in.empty", "-log", "log.txt"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=60,
                          env=dict(os.environ, **serial_mpi_env(tmp_path), OMP_NUM_THREADS="1"))
    assert proc.returncode == 0, proc.stdout + proc.stderr
    for text in (proc.stdout, (tmp_path / "log.txt").read_text()):
        lines = [line for line in text.splitlines() if line.startswith("stickslip ")]
        assert len(lines) == 1 and lines[0].startswith(f"stickslip {VERSION}: "), text
