"""A griffe extension that reads the package's reST-flavoured docstrings as Markdown.

mkdocstrings renders docstrings as Markdown; the package's are NumPy-style sections around reST
prose. What reST writes differently is rewritten in the text handed to the renderer (the package
itself is not touched):

- roles (:class:`X`, :func:`f`, :meth:`m`, :attr:`a`, :data:`D`, :mod:`m`, with ``~`` and
  leading-dot forms) become the name as code, linked to its API entry when the name resolves to
  an object the site documents. The link is an *optional* cross-reference: a name the site does
  not render (a private helper, an undocumented constant) stays plain code and never warns;
- literal blocks (a paragraph ending in ``::`` above an indented block) become fenced code
  blocks, and ``::`` a single colon;
- list items' continuation lines are indented by the 4 columns Markdown needs (reST takes 2), and
  an item right under a paragraph gets the blank line Markdown needs above it;
- a ``Returns`` section written as a sentence (no type line above an indented description)
  becomes the description of the annotated return type, instead of a sentence in the type column.
"""

from __future__ import annotations

import html
import re
from typing import Any

from griffe import Extension, Module, Object

_ROLE = re.compile(r":(?:class|func|meth|attr|data|mod|exc|obj|const):`(~?)([^`]+)`")
_LIST_ITEM = re.compile(r"^\s*(?:[-*+] |\d+\. )")
_SECTION_UNDERLINE = re.compile(r"^\s*-{3,}\s*$")
_FENCED = re.compile(r"(^[ \t]*```.*?^[ \t]*```[ \t]*$)", re.MULTILINE | re.DOTALL)


class RestMarkup(Extension):
    """Rewrite reST roles and literal blocks in every docstring of the loaded package."""

    def on_package(self, *, pkg: Module, **kwargs: Any) -> None:
        for obj in _walk(pkg):
            docstring = obj.docstring
            if docstring is None:
                continue
            text = _prose_returns(_list_indents(_literal_blocks(docstring.value)))
            parts = _FENCED.split(text)  # odd items are fenced blocks: no roles there
            for k in range(0, len(parts), 2):
                parts[k] = _ROLE.sub(lambda match, owner=obj: _role(owner, match), parts[k])
            docstring.value = _list_breaks("".join(parts))


def _walk(obj: Object) -> list[Object]:
    """``obj`` and every object defined under it (imported names are skipped)."""
    found = [obj]
    for member in obj.members.values():
        if member.is_alias:
            continue
        found.extend(_walk(member))  # type: ignore[arg-type]
    return found


def _role(owner: Object, match: re.Match[str]) -> str:
    """The role as code, wrapped in an optional cross-reference when its target resolves."""
    short, target = match.group(1) == "~", re.sub(r"\s+", "", match.group(2))
    shown = target.lstrip(".").rsplit(".", 1)[-1] if short else target.lstrip(".")
    code = f"<code>{html.escape(shown)}</code>"
    path = _resolve(owner, target)
    if path is None:
        return code
    return f'<autoref identifier="{html.escape(path)}" optional>{code}</autoref>'


def _resolve(owner: Object, target: str) -> str | None:
    """The documented path ``target`` names from ``owner``'s scope, or ``None``."""
    module = owner.module
    if target.startswith("."):
        rest = target.lstrip(".")
        scopes = [module.path]
        parent = module.parent
        while parent is not None:
            scopes.append(parent.path)
            parent = parent.parent
        candidates = [f"{scope}.{rest}" for scope in scopes]
    elif target.startswith(module.package.path + "."):
        candidates = [target]
    else:
        head, _, tail = target.partition(".")
        try:
            resolved = owner.resolve(head)
        except Exception:  # griffe's NameResolutionError, or any other failure: no link
            return None
        candidates = [f"{resolved}.{tail}" if tail else resolved]
    collection = owner.modules_collection
    for candidate in candidates:
        try:
            found = collection.get_member(candidate)
        except Exception:  # KeyError, or an alias that cannot be resolved
            continue
        try:
            return str(found.final_target.path) if found.is_alias else str(found.path)
        except Exception:  # an alias to an object outside the package
            return None
    return None


def _literal_blocks(text: str) -> str:
    """reST ``text::`` + indented block → ``text:`` + fenced code block."""
    lines = text.split("\n")
    out: list[str] = []
    i = 0
    while i < len(lines):
        line = lines[i]
        stripped = line.rstrip()
        if not stripped.endswith("::"):
            out.append(line)
            i += 1
            continue
        marker = _LIST_ITEM.match(line)
        indent = len(marker.group(0)) if marker else _indent(line)  # a list item's text column
        j = i + 1
        while j < len(lines) and not lines[j].strip():
            j += 1
        if j == i + 1 or j >= len(lines) or _indent(lines[j]) <= indent:
            out.append(line)  # not a literal block after all
            i += 1
            continue
        end = j
        last = j
        while end < len(lines) and (not lines[end].strip() or _indent(lines[end]) > indent):
            if lines[end].strip():
                last = end
            end += 1
        block = lines[j : last + 1]
        depth = min(_indent(b) for b in block if b.strip())
        head = stripped[:-2].rstrip()
        if head:
            out.append(head + ":")
            out.append("")
        pad = " " * indent
        language = "python" if any(">>>" in b or "import " in b for b in block) else "text"
        out.append(f"{pad}```{language}")
        out.extend(pad + b[depth:] if b.strip() else "" for b in block)
        out.append(f"{pad}```")
        i = last + 1
    return "\n".join(out)


def _list_indents(text: str) -> str:
    """Indent list items' continuation lines to the 4 columns Markdown needs (reST takes 2)."""
    out: list[str] = []
    stack: list[tuple[int, int]] = []  # (reST text column of an open item, columns added there)
    fenced = False
    for line in text.split("\n"):
        if not line.strip():
            out.append(line)
            continue
        column = _indent(line)
        if not fenced:
            while stack and column < stack[-1][0]:
                stack.pop()
        shift = sum(added for _, added in stack)
        marker = None if fenced else _LIST_ITEM.match(line)
        if line.lstrip().startswith("```"):
            fenced = not fenced
        out.append(" " * shift + line)
        if marker:
            width = len(marker.group(0)) - column
            stack.append((column + width, max(0, 4 - width)))
    return "\n".join(out)


def _prose_returns(text: str) -> str:
    """A Returns/Yields section of unindented sentences → ``:`` and the sentences indented."""
    lines = text.split("\n")
    out: list[str] = []
    i = 0
    while i < len(lines):
        out.append(lines[i])
        if (lines[i].strip() in ("Returns", "Yields") and i + 1 < len(lines)
                and _SECTION_UNDERLINE.match(lines[i + 1])):
            base = _indent(lines[i])
            out.append(lines[i + 1])
            j = i + 2
            body: list[str] = []
            while j < len(lines) and lines[j].strip():
                if j + 1 < len(lines) and _SECTION_UNDERLINE.match(lines[j + 1]):
                    break
                body.append(lines[j])
                j += 1
            if body and all(_indent(b) == base for b in body):
                pad = " " * base
                out.append(f"{pad}:")
                out.extend(f"{pad}    {b.strip()}" for b in body)
            else:
                out.extend(body)
            i = j
            continue
        i += 1
    return "\n".join(out)


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def _list_breaks(text: str) -> str:
    """Put a blank line above a list item that Markdown would read as part of a paragraph.

    That is an item right under a block of text that does not itself start as a list: a paragraph
    (legal in reST), or an item's continuation paragraph followed by the next item.
    """
    lines = text.split("\n")
    out: list[str] = []
    fenced = False
    block_start = ""
    for k, line in enumerate(lines):
        if line.lstrip().startswith("```"):
            fenced = not fenced
        previous = lines[k - 1] if k > 0 else ""
        if not previous.strip():
            block_start = line
        elif (not fenced and _LIST_ITEM.match(line) and not _LIST_ITEM.match(block_start)
                and not _SECTION_UNDERLINE.match(previous)):
            out.append("")
            block_start = line
        out.append(line)
    return "\n".join(out)
