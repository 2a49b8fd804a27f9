"""The pip package (pyproject.toml, pip/CMakeLists.txt) stays in step with the catkin package.

pip/CMakeLists.txt globs the core and binding sources that the catkin CMakeLists.txt lists one
by one; the version is written in pyproject.toml and package.xml; the type stubs shipped with the
package (_core.pyi) name every public entry point of the compiled module.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import downstream_perception._core as core

REPO = Path(__file__).resolve().parents[2]


def _catkin_list(call: str) -> set[str]:
    text = (REPO / "CMakeLists.txt").read_text()
    match = re.search(re.escape(call) + r"(.*?)\)", text, re.S)
    assert match, call
    return set(re.findall(r"(src/\S+\.cpp)", match.group(1)))


def _on_disk(folder: str, recursive: bool) -> set[str]:
    root = REPO / folder
    files = root.rglob("*.cpp") if recursive else root.glob("*.cpp")
    return {str(p.relative_to(REPO)) for p in files}


def test_the_pip_build_compiles_the_catkin_core_sources() -> None:
    # What pip/CMakeLists.txt's GLOB_RECURSE picks up is exactly the catkin core library.
    assert _on_disk("src/core", recursive=True) == _catkin_list("add_library(${PROJECT_NAME}_core")


def test_the_pip_build_compiles_the_catkin_binding_sources() -> None:
    assert _on_disk("src/python", recursive=False) == _catkin_list("pybind11_add_module(_core")


def test_versions_agree() -> None:
    pyproject = tomllib.loads((REPO / "pyproject.toml").read_text())
    package_xml = (REPO / "package.xml").read_text()
    version = re.search(r"<version>([^<]+)</version>", package_xml)
    assert version
    assert pyproject["project"]["version"] == version.group(1)
    assert pyproject["project"]["requires-python"] == ">=3.11"


def _public_names() -> set[str]:
    return {n for n in dir(core) if not n.startswith("_")}


def test_the_stubs_name_every_public_entry_point() -> None:
    stub = (REPO / "src" / "downstream_perception" / "_core.pyi").read_text()
    declared = set(re.findall(r"^(?:class|def) (\w+)", stub, re.M))
    declared |= set(re.findall(r"^(\w+)\s*:", stub, re.M))
    missing = sorted(_public_names() - declared)
    assert missing == [], f"{missing}: regenerate with tools/stubs.sh"
    assert (REPO / "src" / "downstream_perception" / "py.typed").is_file()


def _has_doc(obj: object) -> bool:
    # pybind11 puts the signature on the first line; a docstring is whatever follows it.
    lines = [line for line in (obj.__doc__ or "").strip().splitlines() if line.strip()]
    return len(lines) >= 2 or (len(lines) == 1 and "(" not in lines[0].split(" ")[0])


def test_every_class_function_and_method_has_a_docstring() -> None:
    undocumented = []
    for name in sorted(_public_names()):
        obj = getattr(core, name)
        if isinstance(obj, type):
            if not (obj.__doc__ or "").strip():
                undocumented.append(name)
            for member_name, member in vars(obj).items():
                if member_name.startswith("_") or isinstance(member, property):
                    continue
                if callable(member) and not _has_doc(member):
                    undocumented.append(f"{name}.{member_name}")
        elif callable(obj) and not _has_doc(obj):
            undocumented.append(name)
    assert undocumented == []


def test_the_package_exports_every_public_entry_point() -> None:
    # `import downstream_perception as dp` is how the docs use the core: a class bound in C++ but
    # not re-exported in __init__.py is invisible there (VoxelMap was, for a while).
    import downstream_perception as dp

    hidden = sorted(n for n in _public_names() if n != "pybind11_version" and n not in vars(dp))
    assert hidden == [], f"add {hidden} to the import list in downstream_perception/__init__.py"


def test_every_field_has_a_docstring() -> None:
    # help(dp.TsdfConfig) is where a Python user reads what a field means and its unit: each
    # field carries its C++ header comment.
    undocumented = []
    for name in sorted(_public_names()):
        obj = getattr(core, name)
        if not isinstance(obj, type):
            continue
        for member_name, member in vars(obj).items():
            if member_name.startswith("_") or not isinstance(member, property):
                continue
            # pybind11 keeps no docstring on class-level constants (static properties), and an
            # enum's `value` is pybind11's own.
            if type(member).__name__ == "pybind11_static_property" or member_name == "value":
                continue
            if not (member.__doc__ or "").strip():
                undocumented.append(f"{name}.{member_name}")
    assert undocumented == []
