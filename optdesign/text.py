"""Text from a user made safe for each output that shows it.

Names, descriptions, labels and units come from problem files, plug-ins and API calls,
and error messages echo them: any of them may hold a character that means something to
the output it reaches. Each output has one rule, applied where the text is written:

- a terminal (:func:`printable`): control characters (C0, DEL, C1), Unicode format
  characters (bidirectional overrides and isolates, zero-width characters) and the line
  and paragraph separators are shown escaped (``\\x1b``, ``\\u202e``), newlines too
  unless the text is ours and several lines long; every other character, accents, Greek,
  symbols such as degree and micro, is kept;
- a spreadsheet (:func:`csv_cell`): a text cell that starts with ``=``, ``+``, ``-``,
  ``@``, a tab or a carriage return gets a leading ``'`` (OWASP's rule against formula
  injection), numbers are written as numbers;
- HTML and matplotlib have their own rules, next to the code that writes them
  (:func:`optdesign.reports.html_page.to_json`, :func:`optdesign.plots.plain`).

The JSON outputs need no rule for text (JSON strings are safe by construction).
"""

from __future__ import annotations

import numbers
import unicodedata

__all__ = ["FORMULA_START", "csv_cell", "printable"]

#: Unicode categories shown escaped in a terminal: controls, format characters (bidi
#: overrides, zero-width), surrogates (which cannot even be encoded), line and
#: paragraph separators.
_UNSAFE_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Zl", "Zp"})


def _escaped(ch: str) -> str:
    """``\\n``, ``\\x1b``, ``\\u202e``: the character as Python writes it in a literal."""
    return ascii(ch)[1:-1]


def printable(text: object, *, newlines: bool = False) -> str:
    """``text`` as it may reach a terminal: unsafe characters shown escaped.

    Parameters
    ----------
    text
        Any value (``str()`` of it is shown).
    newlines
        Keep ``\\n`` as a line break (a multi-line text of our own that embeds user
        strings); by default a newline is escaped too, so the text stays one line.

    Returns
    -------
    str
        The text with each control character (C0, DEL, C1), format character (e.g. the
        bidi override U+202E), surrogate and line or paragraph separator replaced by its
        escape (``\\x1b``, ``\\r``, ``\\u202e``); every other character unchanged.
    """
    s = str(text)
    if s.isprintable():  # nothing to escape (the common case)
        return s
    out = []
    for ch in s:
        if ch == "\n" and newlines:
            out.append(ch)
        elif ch.isprintable() or unicodedata.category(ch) not in _UNSAFE_CATEGORIES:
            out.append(ch)
        else:
            out.append(_escaped(ch))
    return "".join(out)


#: First characters that make a spreadsheet read a text cell as a formula (OWASP).
FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def csv_cell(value: object, digits: int | None = None) -> object:
    """A value ready for :mod:`csv`: a number stays a number, a text cell that a
    spreadsheet would read as a formula gets a leading ``'``.

    Parameters
    ----------
    value
        A cell: a number (Python or NumPy, bool included), None (an empty cell) or text.
    digits
        Significant digits of a float (``format(v, ".{digits}g")``); None: Python's
        shortest exact form.

    Returns
    -------
    object
        The number (or its formatted text when ``digits`` is given), None, or the text,
        prefixed with ``'`` when it starts with one of :data:`FORMULA_START`. A negative
        number is a number and is not prefixed; the text ``"-1"`` is.
    """
    if value is None:
        return None
    if isinstance(value, numbers.Number):
        if digits is not None and isinstance(value, numbers.Real) and not isinstance(value, bool):
            return format(float(value), f".{digits}g")
        return value
    text = str(value)
    return "'" + text if text.startswith(FORMULA_START) else text
