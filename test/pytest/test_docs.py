"""The docs describe what the code does: every parameter table in docs/ agrees with the .cfg files
(names, types, defaults), the C++ defaults (the bound Config structs and literal defaults in the
ROS glue) and the keys the code reads; units follow the names' suffixes; the README stays short
and every link resolves.

A parameter table is marked by the comment line above it:
    <!-- parameters: cfg=<cfg module> config=<dp class>(<doc name>:<field>, ...) src=<globs> -->
cfg: every parameter of that dynamic_reconfigure module is a row with the same type and default.
config: rows named like a field of that Config (or renamed by the list) have its default.
src: every key those files read is a row of some table listing the file, every row is read
there (or is a cfg or config name), and a literal default in the call equals the row's.
"""

from __future__ import annotations

import importlib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.md"))
# The folders whose sources read ROS parameters (a new reader must be listed by some table).
PARAM_SOURCES = [
    "src/ros/**/*.cpp",
    "src/layers/**/*.cpp",
    "src/costmap_2d/**/*.cpp",
    "scripts/*_node.py",
]

MARKER = re.compile(r"^<!-- parameters: (.*?) -->\n((?:\|.*\n?)+)", re.M)
# A key read by the code: reader.get("key", ...), pnh.param("key", ...), rospy's p("~key", ...).
KEY_READ = re.compile(
    r"(?:\.|->|\b)(?:get|param|getParam|hasParam|searchParam|has|unsupported|take|search|p)(?:<[^>]*>)?\(\s*\"~?([A-Za-z_0-9]+)\""
)
# readParam(pnh, "key", &value, errors): the nodelets' typed reads (param_reader.h).
READ_PARAM = re.compile(r"\breadParam\(\s*[A-Za-z_]\w*\s*,\s*\"~?([A-Za-z_0-9]+)\"")
# Keys read elsewhere and declared to the reader: reader.known({"a", "b"}).
KNOWN = re.compile(r"known\(\{([^}]*)\}\)")
LITERAL = r"(-?[0-9][0-9.e+-]*|true|false|True|False|\"[^\"]*\"|std::string\(\"[^\"]*\"\))"
LITERAL_DEFAULT = re.compile(
    r"(?:\.|->|\b)(?:param|p)(?:<[^>]*>)?\(\s*\"~?([A-Za-z_0-9]+)\"\s*,\s*(?:[A-Za-z_][\w.>-]*\s*,\s*)?"
    + LITERAL
    + r"\s*\)"
)
# Name suffix -> the unit its row must give (REP-103 units in names).
SUFFIX_UNITS = {
    "_m": "m",
    "_s": "s",
    "_hz": "Hz",
    "_mps": "m/s",
    "_rad": "rad",
    "_px": "px",
    "_mb": "MiB",
    "_mib": "MiB",
}


@dataclass
class Row:
    names: list[str]
    type: str
    defaults: dict[str, str]  # name -> raw default text
    unit: str
    image_defaults: dict[str, str] = field(default_factory=dict)


@dataclass
class Table:
    page: str
    line: int
    cfg: str | None
    config: str | None
    renames: dict[str, str]
    sources: list[Path]
    rows: list[Row]

    def row(self, name: str) -> Row | None:
        return next((r for r in self.rows if name in r.names), None)


def cells(line: str) -> list[str]:
    parts = re.split(r"(?<!\\)\|", line.strip())
    return [p.strip() for p in parts[1:-1]]


def split_defaults(names: list[str], text: str) -> dict[str, str]:
    if len(names) == 1:
        return {names[0]: text}
    for sep in (", ", " / "):
        parts = [p.strip() for p in text.split(sep)]
        if len(parts) == len(names):
            return dict(zip(names, parts, strict=True))
    return {name: text for name in names}  # one default for all (e.g. `width`, `height`: 10.0)


def parse_marker(text: str) -> tuple[str | None, str | None, dict[str, str], list[Path]]:
    attrs = dict(re.findall(r"(\w+)=(\S+(?:\([^)]*\))?)", text))
    config, renames = attrs.get("config"), {}
    if config and "(" in config:
        config, inner = config.rstrip(")").split("(", 1)
        renames = dict(pair.split(":") for pair in inner.replace(" ", "").split(",") if pair)
    patterns = [p for p in attrs.get("src", "").split(",") if p]
    sources = [path for pattern in patterns for path in sorted(ROOT.glob(pattern))]
    return attrs.get("cfg"), config, renames, sources


def parse_tables() -> list[Table]:
    tables = []
    for page in PAGES:
        text = page.read_text()
        for match in MARKER.finditer(text):
            lines = match.group(2).strip().splitlines()
            header = [h.strip("`").lower() for h in cells(lines[0])]
            col = {h: i for i, h in enumerate(header)}
            name_col = 0
            type_col = col.get("type")
            default_col = col.get("default", col.get("metric default"))
            image_col = col.get("image default")
            unit_col = next((i for h, i in col.items() if h.startswith("unit")), None)
            rows = []
            for line in lines[2:]:
                c = cells(line)
                if "…" in c[name_col]:
                    continue  # a row pointing to another table
                quoted = re.findall(r"`([^`]+)`", c[name_col])
                names = [re.sub(r"^(~|<[^>]+>/)", "", n) for n in quoted]
                rows.append(
                    Row(
                        names=names,
                        type=c[type_col] if type_col is not None else "",
                        defaults=split_defaults(names, c[default_col]),
                        unit=c[unit_col] if unit_col is not None else "",
                        image_defaults=split_defaults(names, c[image_col]) if image_col else {},
                    )
                )
            cfg, config, renames, sources = parse_marker(match.group(1))
            line_no = text[: match.start()].count("\n") + 1
            tables.append(Table(page.name, line_no, cfg, config, renames, sources, rows))
    return tables


TABLES = parse_tables()


def literal(text: str) -> object:
    """A documented default as a value, or None when it is prose ("the costmap's", "unset")."""
    t = text.replace("−", "-").strip()
    if t in ('""', '`""`'):
        return ""
    m = re.fullmatch(r"`([^`]*)`", t)
    if m:
        return m.group(1)
    if t in ("true", "false"):
        return t == "true"
    try:
        return float(t)
    except ValueError:
        return None


def code_literal(text: str) -> object:
    t = text.strip()
    m = re.fullmatch(r'(?:std::string\()?"([^"]*)"\)?', t)
    if m:
        return m.group(1)
    if t in ("true", "True", "false", "False"):
        return t in ("true", "True")
    return float(t)


def same(doc: object, value: object) -> bool:
    if isinstance(value, bool) or isinstance(doc, bool):
        return doc is value or doc == value
    if isinstance(value, int | float) and isinstance(doc, float):
        return math.isclose(doc, float(value), rel_tol=1e-9, abs_tol=1e-12)
    return doc == value


def keys_read(path: Path) -> set[str]:
    text = path.read_text()
    declared = {k for group in KNOWN.findall(text) for k in re.findall(r'"(\w+)"', group)}
    return set(KEY_READ.findall(text)) | set(READ_PARAM.findall(text)) | declared


def test_tables_are_found_and_parsed() -> None:
    # Every component with parameters has its table (a renamed heading must not drop one).
    assert len(TABLES) >= 14, [(t.page, t.line) for t in TABLES]
    for t in TABLES:
        assert t.rows, f"{t.page}:{t.line}: empty table"
        for row in t.rows:
            assert row.names, f"{t.page}:{t.line}: a row without a `name`"


def cfg_parameters(module_name: str) -> list[dict[str, object]]:
    config = importlib.import_module(f"downstream_perception.cfg.{module_name}")
    found: list[dict[str, object]] = []

    def walk(group: dict[str, object]) -> None:
        found.extend(group.get("parameters", []))  # type: ignore[arg-type]
        for sub in group.get("groups", []):  # type: ignore[union-attr]
            walk(sub)

    walk(config.config_description)
    return found


def test_every_cfg_file_has_a_table() -> None:
    documented = {t.cfg for t in TABLES if t.cfg}
    for path in sorted((ROOT / "cfg").glob("*.cfg")):
        assert f"{path.stem}Config" in documented, f"cfg/{path.name}: no parameter table in docs/"


def test_cfg_parameters_documented_with_type_and_default() -> None:
    pytest.importorskip("dynamic_reconfigure")
    pytest.importorskip("downstream_perception.cfg", reason="generated by the catkin build")
    types = {"double": "double", "int": "int", "bool": "bool", "str": "string"}
    for t in (t for t in TABLES if t.cfg):
        for p in cfg_parameters(t.cfg):
            name = str(p["name"])
            row = t.row(name)
            assert row is not None, f"{t.page}:{t.line}: {t.cfg} parameter `{name}` is undocumented"
            if row.type:
                assert row.type == types[str(p["type"])], f"{name}: type {row.type} vs {p['type']}"
            doc = literal(row.defaults[name])
            assert doc is not None, f"{name}: default '{row.defaults[name]}' is not a value"
            assert same(doc, p["default"]), f"{t.page}: `{name}` is {doc}, cfg {p['default']}"


def test_cpp_config_defaults_match() -> None:
    dp = pytest.importorskip("downstream_perception")
    checked = 0
    for t in (t for t in TABLES if t.config):
        config = getattr(dp, t.config)()
        for row in t.rows:
            for name in row.names:
                field_name = t.renames.get(name, name)
                if not hasattr(config, field_name):
                    continue
                value = getattr(config, field_name)
                doc = literal(row.defaults[name])
                if hasattr(value, "name"):  # a bound enum: documented by its name, any case
                    value = value.name.lower()
                    doc = row.defaults[name].strip("`*").lower()
                assert doc is not None and same(doc, value), (
                    f"{t.page}:{t.line}: `{name}` documented {row.defaults[name]}, "
                    f"{t.config}.{field_name} = {value}"
                )
                checked += 1
    assert checked >= 40


def test_tracker_image_defaults_match() -> None:
    dp = pytest.importorskip("downstream_perception")
    image = dp.TrackerConfig.defaults_for(dp.TrackerConfig.Mode.IMAGE)
    table = next(t for t in TABLES if t.config == "TrackerConfig")
    checked = 0
    for row in table.rows:
        for name, text in row.image_defaults.items():
            value = getattr(image, name)
            if hasattr(value, "name"):  # the mode: IMAGE
                assert text.strip("`*") == value.name, f"IMAGE `{name}`: {text} vs {value.name}"
                checked += 1
                continue
            doc = literal(text.replace("*", ""))
            if doc is None:
                assert text == "(unused)", f"IMAGE `{name}`: '{text}' is not a value"
                continue
            assert same(doc, value), f"IMAGE `{name}`: {text} vs {value}"
            checked += 1
    assert checked >= 8


def test_every_key_the_code_reads_is_documented() -> None:
    listed: dict[Path, set[str]] = {}
    for t in TABLES:
        for path in t.sources:
            listed.setdefault(path, set()).update(n for r in t.rows for n in r.names)
    readers = {p for pattern in PARAM_SOURCES for p in ROOT.glob(pattern) if keys_read(p)}
    unlisted = sorted(str(p.relative_to(ROOT)) for p in readers - set(listed))
    assert not unlisted, f"read ROS parameters but no docs table lists them as src: {unlisted}"
    for path, documented in listed.items():
        missing = sorted(keys_read(path) - documented)
        assert not missing, f"{path.relative_to(ROOT)} reads undocumented keys: {missing}"


def test_every_documented_key_is_read() -> None:
    for t in (t for t in TABLES if t.sources):
        read = set().union(*(keys_read(p) for p in t.sources))
        if t.cfg:
            if not _has_cfg():
                continue  # the cfg's names are read by its dynamic_reconfigure server
            read |= {str(p["name"]) for p in cfg_parameters(t.cfg)}
        stale = [n for r in t.rows for n in r.names if n not in read]
        assert not stale, f"{t.page}:{t.line}: documented but never read: {stale}"


def _has_cfg() -> bool:
    try:
        importlib.import_module("dynamic_reconfigure")
        importlib.import_module("downstream_perception.cfg")
    except ImportError:
        return False
    return True


def test_literal_defaults_in_code_match_the_docs() -> None:
    checked = 0
    for t in (t for t in TABLES if t.sources):
        for path in t.sources:
            for key, value in LITERAL_DEFAULT.findall(path.read_text()):
                row = t.row(key)
                if row is None:
                    continue
                doc = literal(row.defaults[key])
                assert doc is not None and same(doc, code_literal(value)), (
                    f"{path.relative_to(ROOT)}: `{key}` defaults to {value} in the code, "
                    f"{row.defaults[key]} in {t.page}:{t.line}"
                )
                checked += 1
    assert checked >= 30


def test_units_follow_the_names() -> None:
    for t in TABLES:
        for row in t.rows:
            for name in row.names:
                for suffix, unit in SUFFIX_UNITS.items():
                    if name.endswith(suffix):
                        text = row.unit.replace("m/s", "mps")
                        units = [u.strip() for u in re.split(r"[,/]| or ", text)]
                        units = ["m/s" if u == "mps" else u for u in units]
                        where = f"{t.page}:{t.line}: `{name}`"
                        assert unit in units, f"{where} needs unit {unit}, has '{row.unit}'"


def slug(heading: str) -> str:
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def test_readme_is_short_and_links_resolve() -> None:
    readme = ROOT / "README.md"
    assert len(readme.read_text().splitlines()) <= 250
    linked = set(re.findall(r"\]\((docs/[^)#]+)", readme.read_text()))
    for page in PAGES:
        assert f"docs/{page.name}" in linked, f"README does not link docs/{page.name}"
    for doc in [readme, *PAGES]:
        for target in re.findall(r"\]\(([^)\s]+)\)", doc.read_text()):
            if re.match(r"[a-z]+://", target):
                continue
            path, _, anchor = target.partition("#")
            resolved = (doc.parent / path) if path else doc
            assert resolved.exists(), f"{doc.name}: broken link {target}"
            if anchor:
                headings = re.findall(r"^#+ (.*)$", resolved.read_text(), re.M)
                assert anchor in {slug(h) for h in headings}, f"{doc.name}: no anchor {target}"


def test_every_bound_name_is_in_the_python_page() -> None:
    core = pytest.importorskip("downstream_perception._core", reason="compiled core not built")
    text = (DOCS / "python.md").read_text()
    public = {n for n in dir(core) if not n.startswith("_") and n != "pybind11_version"}
    missing = sorted(n for n in public if f"`{n}`" not in text)
    assert not missing, f"docs/python.md does not list {missing}"


def test_replay_options_table_matches_the_parser() -> None:
    cli = ROOT / "src" / "downstream_perception" / "replay" / "cli.py"
    options = re.findall(r'add_argument\(\s*"(--[\w-]+)"', cli.read_text())
    text = (DOCS / "replay.md").read_text()
    table = text[text.index("| option | default | meaning |") :].split("\n\n", 1)[0]
    documented: dict[str, str] = {}
    for line in table.splitlines()[2:]:
        c = cells(line)
        names = re.findall(r"`(--[\w-]+)`", c[0])
        documented.update(split_defaults(names, c[1]))
    assert sorted(documented) == sorted(options)
    parse = pytest.importorskip("downstream_perception.replay.cli", reason="needs rosbag").parse
    defaults = vars(parse(["my.bag", "--config", "c.yaml"]))  # one capability is required
    for option, text_default in documented.items():
        if option == "--config":
            continue
        value = defaults[option[2:].replace("-", "_")]
        if value is None or value is False:
            assert text_default in ("", "off"), f"{option}: documented '{text_default}'"
        else:
            assert same(
                literal(text_default), value if not isinstance(value, Path) else str(value)
            ), f"{option}: documented '{text_default}', parser {value}"
