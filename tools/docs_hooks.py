"""MkDocs hooks of the documentation site (``mkdocs.yml``: ``hooks: [tools/docs_hooks.py]``).

Pages generated from the code at build time, so that they cannot drift from it:

- ``commands/<name>.md``: one page per command of ``python -m semianalytic`` and
  ``python -m fem_check``, from the commands' own argparse parsers, with the README's
  examples of that command;
- ``case-reference.md``: every case-file section and key from the pydantic schemas (unit,
  default, allowed values, range, description);
- ``examples.md``: the gallery, one entry per script of ``docs/examples/`` (its docstring and
  its source; ``tests/test_docs.py`` runs every script).

The navigation is generated too: the fixed pages first, then every other ``docs/*.md`` in
alphabetical order, so a page added on another branch (``docs/cluster.md``) appears without
editing ``mkdocs.yml``.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import re
import typing
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# The fixed head of the navigation; every other docs/*.md follows under "Topics".
FIXED = ["index.md", "getting-started.md", "case-reference.md", "api.md", "examples.md"]


# --------------------------------------------------------------------------------------
# commands


def command_tables() -> list[tuple[str, str, dict]]:
    """``(program, page stem, {name: (module, help)})`` of both command-line tools."""
    from fem_check.cli import COMMANDS as FEM
    from semianalytic.cli import COMMANDS as SEMI

    return [("python -m semianalytic", "semianalytic", SEMI), ("python -m fem_check", "fem_check", FEM)]


def _md_escape(text: str) -> str:
    return (text or "").replace("|", "\\|").replace("*", "\\*").replace("<", "&lt;").replace("_", "\\_")


def _module(module_name: str):
    if module_name.startswith("benchmarks."):  # the checkout's benchmarks/ (not installed), as the CLI does
        from semianalytic.checkout import import_benchmark

        return import_benchmark(module_name, module_name)
    return importlib.import_module(module_name)


def _parser(prog: str, name: str, module_name: str, help_: str) -> argparse.ArgumentParser:
    from semianalytic.cli_types import OneLineParser

    module = _module(module_name)
    parser = OneLineParser(prog=f"{prog} {name}", description=help_)
    module.add_arguments(parser)
    parser.add_argument("--memory-limit", default=None, metavar="SIZE",
                        help="memory budget, e.g. 8GB (default: $SEMIANALYTIC_MEMORY_LIMIT, else 4GB); "
                             "larger problems are refused before they start")
    return parser


def readme_examples(prog: str, name: str) -> list[str]:
    """The README's shell lines that run this command (they run verbatim: tests/test_readme_commands.py)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    module = prog.split()[-1]
    out = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        for line in block.splitlines():
            cmd = re.sub(r"\s+#.*$", "", line.strip())
            if re.match(rf"(\.venv/bin/)?python -m {re.escape(module)} {re.escape(name)}(\s|$)", cmd):
                out.append(cmd)
    return out


def command_page(prog: str, name: str, module_name: str, help_: str) -> str:
    """The Markdown page of one command, from its parser."""
    parser = _parser(prog, name, module_name, help_)
    usage = parser.format_usage().replace("usage: ", "").strip()
    lines = [f"# `{prog} {name}`", "", _md_escape(help_[:1].upper() + help_[1:]) + ".", ""]
    doc = inspect.getdoc(_module(module_name)) or ""
    doc = re.sub(r":\w+:`~?([^`]+)`", r"`\1`", doc).replace("``", "`")  # reST roles and literals as Markdown code
    paragraphs = [p for p in doc.split("\n\n") if p.strip()]
    if paragraphs and paragraphs[0].strip().startswith("`python -m"):
        paragraphs = paragraphs[1:]  # the usage line: the section below says it
    prose = [" ".join(p.split()) for p in paragraphs if not p.lstrip().startswith(("-", "|", "    "))]
    if prose:
        lines += ["", *[f"{p}\n" for p in prose]]
    lines += ["## Usage", "", "```text", usage, "```", "", "## Arguments and options", "",
              "| argument | value | default | description |", "|---|---|---|---|"]
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        names = ", ".join(f"`{s}`" for s in action.option_strings) or f"`{action.metavar or action.dest}`"
        if action.choices:
            value = " \\| ".join(f"`{c}`" for c in action.choices)
        elif action.nargs == 0:
            value = "flag"
        else:
            value = f"`{action.metavar or action.dest.upper()}`"
        if action.nargs in ("+", "*") or isinstance(action, argparse._AppendAction):
            value += " (repeatable)" if action.option_strings else " (one or more)"
        default = action.default
        shown = "" if default in (None, False, argparse.SUPPRESS) or action.nargs == 0 else f"`{default}`"
        if not action.option_strings:
            shown = "required"
        lines.append(f"| {names} | {value} | {shown} | {_md_escape(' '.join((action.help or '').split()))} |")
    examples = readme_examples(prog, name)
    if examples:
        lines += ["", "## Examples (from the README, run verbatim by the test suite)", "", "```sh", *examples, "```"]
    lines += ["", "Exit status: 0 success, 2 bad input (one line `error: <field>: <message>`), 1 internal failure.", ""]
    return "\n".join(lines)


def commands_index() -> str:
    lines = ["# Commands", "", "Every command prints `--help`; both tools print `--version`. "
             "Bad input ends with exit status 2 and one line naming the field.", ""]
    for prog, stem, table in command_tables():
        lines += [f"## `{prog}`", "", "| command | what it does |", "|---|---|"]
        lines += [f"| [`{name}`]({stem}-{name}.md) | {_md_escape(help_)} |" for name, (_, help_) in table.items()]
        lines.append("")
    return "\n".join(lines)


# --------------------------------------------------------------------------------------
# case-file reference


def _constraints(field) -> str:
    """The range of a field from its annotated-types metadata (gt, ge, lt, le, lengths)."""
    out = []
    for m in field.metadata:
        for attr, sym in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            v = getattr(m, attr, None)
            if v is not None:
                out.append(f"{sym} {v:g}" if isinstance(v, (int, float)) else f"{sym} {v}")
        if getattr(m, "min_length", None):
            out.append(f"at least {m.min_length} item{'s' if m.min_length > 1 else ''}")
        if getattr(m, "pattern", None):
            out.append("letters, digits, `_.-`")
    return ", ".join(out)


def _quantity(annotation) -> tuple[str, str] | None:
    """(kind, sign) of a quantity annotation (a unit string checked by semianalytic.units)."""
    for m in getattr(annotation, "__metadata__", ()):
        kind = getattr(getattr(m, "func", None), "quantity_kind", None)
        if kind:
            return kind, m.func.sign
    for a in typing.get_args(annotation):
        q = _quantity(a)
        if q:
            return q
    return None


def type_text(annotation) -> str:
    """What a key takes, in the case files' words (unit strings with their SI unit)."""
    from pydantic import BaseModel

    from semianalytic.schema import allowed_values
    from semianalytic.units import KINDS

    q = _quantity(annotation)
    origin = typing.get_origin(annotation)
    if origin in (list, tuple) and q is None:
        args = [a for a in typing.get_args(annotation) if a is not Ellipsis]
        inner = args[0] if args else typing.Any
        if typing.get_origin(inner) is tuple:
            return "list of pairs `[[a, b], ...]` of numbers"
        return f"list of {type_text(inner)}"
    if q is not None:
        kind, sign = q
        _, si, example = KINDS[kind]
        prefix = "list of " if origin is list or (typing.get_origin(annotation) in (typing.Union,) and False) else ""
        text = f"{kind.replace('_', ' ')} (unit string, SI unit {si}, e.g. `\"{example}\"`)"
        if sign:
            text += f", {sign}"
        if any(typing.get_origin(a) is list for a in typing.get_args(annotation)):
            prefix = "list of "
        return prefix + text
    if allowed_values(annotation):
        return "one of the allowed values"
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return "table"
    args = [a for a in typing.get_args(annotation) if a is not type(None)]
    if origin is not None and args and origin not in (dict,):
        if all(isinstance(a, type) and issubclass(a, BaseModel) for a in args):
            return "table"
        if len(args) == 1:
            return type_text(args[0])
        if typing.get_origin(annotation) is typing.Annotated:
            return type_text(args[0])
    if origin is dict:
        return "table of text lists"
    return {float: "number", int: "integer", bool: "true or false", str: "text"}.get(annotation, str(annotation))


def _default_text(field, si_unit: str = "") -> str:
    if field.is_required():
        return "**required**"
    if field.default_factory is not None:
        value = field.default_factory()
        return "empty" if not value else f"`{value}`"
    if field.default is None:
        return "none (optional)"
    if si_unit and isinstance(field.default, (int, float)):
        return f"`{field.default:g} {si_unit}`"
    return f"`{field.default!r}`" if isinstance(field.default, str) else f"`{field.default}`"


def _allowed_text(field) -> str:
    from semianalytic.schema import allowed_values

    values = allowed_values(field.annotation)
    rng = _constraints(field)
    if values:
        return ", ".join(f"`{v}`" for v in values)
    return rng


def _doc_paragraph(cls) -> str:
    doc = inspect.cleandoc(cls.__dict__.get("__doc__") or "")  # its own, not pydantic's BaseModel's
    doc = re.sub(r":\w+:`~?([^`]+)`", r"`\1`", doc).replace("``", "`")  # reST roles and literals as Markdown code
    return " ".join(doc.split("\n\n")[0].split())


def source_comments(model) -> dict[str, str]:
    """``key: comment`` of the schema's own source: the comment at the end of a field's line
    (``max_depth: float = 300.0  # in nose lengths``) or on the line just above it."""
    try:
        src = inspect.getsource(model)
    except (OSError, TypeError):
        return {}
    out, above = {}, ""
    for line in src.splitlines():
        stripped = line.strip()
        if stripped.startswith("#"):
            above = (above + " " + stripped.lstrip("# ")).strip()
            continue
        m = re.match(r"(\w+)\s*:[^#]*?(?:#\s*(.*))?$", stripped)
        if m and m.group(1) in model.model_fields:
            text = m.group(2) or above
            if text and "noqa" not in text:
                out[m.group(1)] = text.strip()
        above = ""
    return out


def section_table(name: str, model, heading: str | None = None) -> list[str]:
    """Markdown of one section: its docstring, then one row per key (nested tables after it)."""
    from pydantic import BaseModel

    from semianalytic.schema import _models_in, allowed_values, key_description

    lines = [heading or f"## `[{name}]`", ""]
    para = _doc_paragraph(model)
    if para:
        lines += [_md_escape(para).replace("\\_", "_") if "`" in para else _md_escape(para), ""]
    lines += ["| key | value | default | allowed values / range | description |", "|---|---|---|---|---|"]
    from semianalytic.units import KINDS

    comments = source_comments(model)
    nested = []
    for key, field in model.model_fields.items():
        annotation = typing.Annotated[(field.annotation, *field.metadata)] if field.metadata else field.annotation
        q = _quantity(annotation)
        si = KINDS[q[0]][1] if q else ""
        lines.append(f"| `{key}` | {type_text(annotation)} | {_default_text(field, si)} | {_allowed_text(field)} | "
                     f"{_md_escape(key_description(model, key, si, comments.get(key, '')))} |")
        members = [m for m in _models_in(field.annotation) if issubclass(m, BaseModel)]
        if members:
            nested.append((key, members))
    lines.append("")
    for key, members in nested:
        for m in members:
            tag = m.model_fields.get("model")
            label = f' with `model = "{allowed_values(tag.annotation)[0]}"`' if tag is not None and allowed_values(tag.annotation) else ""
            lines += section_table(f"{name}.{key}", m, f"### `[{name}.{key}]`{label}")
    return lines


def case_reference() -> str:
    """The whole case-file reference, section by section, from the schemas."""
    from semianalytic.case import _CORE, _META_KEYS, SECTIONS, _section_model

    lines = ["# Case-file reference", "",
             "Generated from the pydantic schemas of the case layer at every build of this site "
             "(`tools/docs_hooks.py`): what is listed here is what the code accepts.", "",
             "A case file is TOML. Quantities are unit strings (`\"7.11 mm\"`, `\"400 MPa\"`, `\"1.0 km/s\"`), "
             "parsed with pint and checked for dimension; plain numbers are TOML numbers (`crh = 3.0`, not `\"3\"`). "
             "An unknown key is refused with its closest valid key (`did you mean 'diameter'?`), a wrong choice "
             "with the allowed values; exit status 2, nothing written.", "",
             "Top-level keys (text): " + ", ".join(f"`{k}`" for k in sorted(_META_KEYS)) + ".", ""]
    for name in [*_CORE, *SECTIONS]:
        lines += section_table(name, _section_model(name))
    return "\n".join(lines)


# --------------------------------------------------------------------------------------
# examples gallery


def example_scripts() -> list[Path]:
    return sorted((ROOT / "docs" / "examples").glob("*.py"))


def gallery() -> str:
    lines = ["# Examples", "",
             "Plain Python scripts in `docs/examples/`, each run by the test suite (`tests/test_docs.py`) and "
             "finished in seconds. Run one from the repository root: `.venv/bin/python docs/examples/NAME.py`.", ""]
    for path in example_scripts():
        src = path.read_text(encoding="utf-8")
        doc = ""
        m = re.match(r'\s*"""(.*?)"""', src, re.S)
        if m:
            doc = m.group(1).strip()
        title = doc.splitlines()[0].rstrip(".") if doc else path.stem
        rest = "\n".join(doc.splitlines()[1:]).strip()
        lines += [f"## {title}", "", f"`docs/examples/{path.name}`", ""]
        if rest:
            lines += [rest, ""]
        lines += ["```python", src.rstrip(), "```", ""]
    return "\n".join(lines)


# --------------------------------------------------------------------------------------
# navigation and the hooks


def generated_pages() -> dict[str, str]:
    """Every generated page: ``{path under docs/: Markdown}``."""
    pages = {"case-reference.md": case_reference(), "examples.md": gallery(), "commands/index.md": commands_index()}
    for prog, stem, table in command_tables():
        for name, (module, help_) in table.items():
            pages[f"commands/{stem}-{name}.md"] = command_page(prog, name, module, help_)
    return pages


def navigation(docs_dir: Path) -> list:
    """Fixed pages, the commands, then every other Markdown page of ``docs/`` (any branch's)."""
    nav = [{"Home": "index.md"}, {"Getting started": "getting-started.md"}]
    commands = [{"Overview": "commands/index.md"}]
    for prog, stem, table in command_tables():
        commands += [{f"{prog.split()[-1]} {name}": f"commands/{stem}-{name}.md"} for name in table]
    nav.append({"Commands": commands})
    nav += [{"Case-file reference": "case-reference.md"}, {"Python API": "api.md"}, {"Examples": "examples.md"}]
    topics = sorted(p.name for p in docs_dir.glob("*.md") if p.name not in FIXED)
    if topics:
        nav.append({"Topics": [{_title(docs_dir / t): t} for t in topics]})
    return nav


def _title(path: Path) -> str:
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("# "):
            return line[2:].strip().strip("`")
    return path.stem.replace("-", " ").replace("_", " ").capitalize()


def on_config(config, **kwargs):
    config["nav"] = navigation(Path(config["docs_dir"]))
    return config


def on_files(files, config, **kwargs):
    from mkdocs.structure.files import File

    for src_uri, content in generated_pages().items():
        existing = files.get_file_from_path(src_uri)
        if existing is not None:
            files.remove(existing)
        files.append(File.generated(config, src_uri, content=content))
    return files
