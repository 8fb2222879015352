"""Student-controlled text made inert for where the grader writes it: a terminal, markdown, a CSV cell.

Names (file and folder names), exception messages, printed output and returned values are written
by students. Before any of it reaches the instructor's terminal, a feedback file or the gradebook,
:func:`clean` removes terminal escape sequences and control and format characters (bidirectional
overrides included), replaces lone surrogates and bounds the length; :func:`md_inline`,
:func:`fenced` and :func:`csv_cell` then quote what is left for markdown and spreadsheets.
"""
from __future__ import annotations

import re
import unicodedata
from typing import Iterable

__all__ = ["clean", "md_inline", "fenced", "csv_cell"]

# CSI (ESC [ ... final), OSC (ESC ] ... BEL or ST), DCS/SOS/PM/APC (ESC P|X|^|_ ... ST), two-byte
# ESC sequences, and the 8-bit CSI
_ESCAPE_SEQUENCE = re.compile(r"\x1b(?:\[[0-?]*[ -/]*[@-~]?|\][^\x07\x1b]*(?:\x07|\x1b\\)?"
                              r"|[PX^_][^\x1b]*(?:\x1b\\)?|[ -~]?)|\x9b[0-?]*[ -/]*[@-~]?")
_BREAKS = "\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"
_DROPPED = ("Cc", "Cf", "Cs", "Zl", "Zp")
_MD_PUNCTUATION = re.compile(r"([!-/:-@\[-`{-~])")
_FORMULA_START = "=+-@\uff1d\uff0b\uff0d\uff20"


def clean(text: object, limit: int, *, lines: bool = False) -> str:
    """Return ``text`` without escape sequences or control/format characters, at most ``limit`` long.

    Tabs become spaces; line breaks are kept (as ``\\n``) when ``lines`` is true and become spaces
    otherwise; a lone surrogate (from a name that is not UTF-8) becomes ``?``; text cut at ``limit``
    ends with ``…``.

    Examples
    --------
    >>> clean("\\x1b[31mred\\x1b[0m\\tand\\u202egreen\\n", 80)
    'red andgreen '
    """
    if not isinstance(text, str):
        text = str(text)
    text = text[: 4 * limit + 64].encode("utf-8", "replace").decode("utf-8")
    text = _ESCAPE_SEQUENCE.sub("", text.replace("\r\n", "\n"))
    out = []
    for ch in text:
        if ch in _BREAKS:
            out.append("\n" if lines and ch != "\r" else " ")
        elif ch == "\t":
            out.append(" ")
        elif unicodedata.category(ch) not in _DROPPED:
            out.append(ch)
    text = "".join(out)
    return text if len(text) <= limit else text[: max(0, limit - 1)] + "…"


def md_inline(text: object, limit: int = 200) -> str:
    """:func:`clean` text on one line with every ASCII punctuation character backslash-escaped, so
    that markdown shows it literally (no emphasis, links, HTML or headings).

    Examples
    --------
    >>> md_inline("**Score: 3 / 3** <b>")
    '\\\\*\\\\*Score\\\\: 3 \\\\/ 3\\\\*\\\\* \\\\<b\\\\>'
    """
    return _MD_PUNCTUATION.sub(r"\\\1", clean(text, limit))


def fenced(lines: Iterable[object], limit: int = 600, max_lines: int = 60) -> list[str]:
    """A markdown code block holding ``lines`` (each :func:`clean`, at most ``max_lines``): its fence
    of backticks is longer than any run of backticks inside, so the text cannot close it.

    Examples
    --------
    >>> fenced(["a ``` b"])
    ['````text', 'a ``` b', '````']
    """
    body = [clean(line, limit) for line in list(lines)[:max_lines]]
    longest = max((len(run) for line in body for run in re.findall(r"`+", line)), default=0)
    fence = "`" * max(3, longest + 1)
    return [f"{fence}text", *body, fence]


def csv_cell(text: object, limit: int = 300) -> str:
    """:func:`clean` text for one gradebook cell; a leading ``=``, ``+``, ``-`` or ``@`` (which a
    spreadsheet would run as a formula) is neutralised with a leading apostrophe.

    Examples
    --------
    >>> csv_cell('=HYPERLINK("http://x")')
    '\\'=HYPERLINK("http://x")'
    """
    text = clean(text, limit)
    return "'" + text if text.lstrip()[:1] in tuple(_FORMULA_START) else text
