"""A CSV file as spreadsheets and stand PCs write it: encoding, preamble, separators, decimals.

Splits the text into the preamble (``--skip-rows`` lines, then comment and blank lines
before the header), the header and the data lines, keeping every data line's number in
the file, so an error names the line a person sees in an editor.
"""

from __future__ import annotations

import codecs
import io
import re
import warnings
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from recordings.errors import ImportMappingError, listed

__all__ = ["CsvOptions", "CsvText", "shorten", "split_csv"]

#: Separators tried on the header line, the most frequent one wins.
SEPARATORS = ",;\t"
_SHOWN = 60  # characters of an offending line shown in an error


@dataclass(frozen=True)
class CsvOptions:
    """How to read a CSV file.

    Attributes
    ----------
    decimal
        ``.`` or ``,`` (then the separator must be ``;`` or tab, as spreadsheets write).
    skip_rows
        Lines skipped at the top whatever they hold (a preamble without comment marks).
    comment
        Lines starting with it are skipped (before the header: the preamble, kept as the
        import note); empty for none.
    encoding
        Text encoding of the file (``utf-8``, ``latin-1``, ``cp1252``, ...); a UTF-8 byte
        order mark is skipped.
    """

    decimal: str = "."
    skip_rows: int = 0
    comment: str = "#"
    encoding: str = "utf-8"

    def check(self) -> None:
        """Raise ImportMappingError for an option that cannot work."""
        if self.decimal not in {".", ","}:
            raise ImportMappingError(f"--decimal {self.decimal!r}: use '.' or ','")
        if self.skip_rows < 0:
            raise ImportMappingError(f"--skip-rows {self.skip_rows}: must be 0 or more")
        if len(self.comment) > 1:
            raise ImportMappingError(f"--comment {self.comment!r}: must be one character")
        try:
            codecs.lookup(self.encoding)
        except LookupError:
            raise ImportMappingError(f"--encoding {self.encoding!r}: unknown encoding") from None
        try:  # hex, rot13, base64, zlib: codecs of bytes to bytes, not text
            "a".encode(self.encoding)
        except UnicodeError:
            pass  # a text encoding that cannot write "a": decoding the file will tell
        except LookupError:
            raise ImportMappingError(
                f"--encoding {self.encoding!r}: not a text encoding "
                "(use utf-8, latin-1, cp1252, ...)"
            ) from None


@dataclass
class CsvText:
    """A CSV file split into its parts; ``table()`` parses the data."""

    where: str
    preamble: list[str]
    header: str
    header_line: int  # 1-based line number in the file
    lines: list[str]  # data lines, blank and comment lines left out
    line_numbers: NDArray[np.int64]  # 1-based file line number of each data line
    separator: str
    options: CsvOptions = field(default_factory=CsvOptions)

    def at(self, row: int) -> str:
        """'line N: <the line>' for data row ``row`` (0-based), for error messages."""
        return f"line {int(self.line_numbers[row])}: {shorten(self.lines[row])}"

    def table(self) -> pd.DataFrame:
        """The data as a DataFrame of the header's columns (numbers parsed where they can be).

        Raises ImportMappingError naming the line for a row with more fields than the header.
        """
        columns = [c.strip() for c in self.header.split(self.separator)]
        twice = sorted(c for c, n in Counter(columns).items() if n > 1)  # linear: 30 000 names
        if twice:
            raise ImportMappingError(
                f"{self.where}: line {self.header_line}: column(s) named twice: {listed(twice)}"
            )
        text = "\n".join(self.lines)
        try:
            with warnings.catch_warnings():  # a row of another length: refused below, one line
                warnings.simplefilter("ignore", pd.errors.ParserWarning)
                frame = pd.read_csv(
                    io.StringIO(text),
                    sep=self.separator,
                    names=columns,
                    header=None,
                    decimal=self.options.decimal,
                    skipinitialspace=True,
                    skip_blank_lines=False,
                    index_col=False,
                    low_memory=False,
                )
        except pd.errors.ParserError as err:
            raise self._parser_error(err, len(columns)) from err
        except pd.errors.EmptyDataError:
            frame = pd.DataFrame({c: pd.Series(dtype=float) for c in columns})
        return frame

    def _parser_error(self, err: pd.errors.ParserError, fields: int) -> ImportMappingError:
        found = re.search(r"line (\d+), saw (\d+)", str(err))
        if found is None:
            return ImportMappingError(f"{self.where}: not a readable CSV file: {err}")
        row = int(found[1]) - 1
        hint = " (a preamble? skip it with --skip-rows N)" if fields == 1 else ""
        return ImportMappingError(
            f"{self.where}: {self.at(row)}: {found[2]} fields where the header "
            f"(line {self.header_line}) has {fields}{hint}"
        )


def shorten(line: str, limit: int = _SHOWN) -> str:
    """The line as a quoted string, cut to about ``limit`` characters."""
    return repr(line if len(line) <= limit else line[: limit - 1] + "…")


def _decode(path: Path, options: CsvOptions) -> str:
    raw = path.read_bytes()
    try:
        text = raw.decode(options.encoding)
    except UnicodeDecodeError as err:
        number = raw.count(b"\n", 0, err.start) + 1
        line = raw.splitlines()[number - 1].decode(options.encoding, errors="replace")
        raise ImportMappingError(
            f"{path}: line {number}: not {options.encoding} text (byte {raw[err.start]:#04x}; "
            f"try --encoding latin-1 or cp1252): {shorten(line)}"
        ) from None
    return text.removeprefix("\ufeff")


def _is_skipped(line: str, comment: str) -> bool:
    stripped = line.strip()
    return not stripped or (bool(comment) and stripped.startswith(comment))


def split_csv(path: Path, options: CsvOptions | None = None) -> CsvText:
    """Read and split a CSV file; the separator is the header line's commonest of , ; tab.

    Raises
    ------
    ImportMappingError
        Undecodable bytes (with the line), no header, or comma decimals with a comma
        separator.
    """
    opts = options or CsvOptions()
    opts.check()
    where = str(path)
    all_lines = _decode(path, opts).splitlines()
    preamble = [line for line in all_lines[: opts.skip_rows] if line.strip()]
    at = opts.skip_rows
    while at < len(all_lines) and _is_skipped(all_lines[at], opts.comment):
        if all_lines[at].strip():
            preamble.append(all_lines[at])
        at += 1
    if at >= len(all_lines):
        raise ImportMappingError(f"{where}: no header line (the file holds no data)")
    header = all_lines[at]
    separator = max(SEPARATORS, key=header.count)
    if separator not in header:  # one column (or a preamble line taken as the header)
        separator = ";" if opts.decimal == "," else ","
    if opts.decimal == "," and separator == ",":
        raise ImportMappingError(
            f"{where}: line {at + 1}: with --decimal , the separator must be ';' or tab, "
            f"found ',' in the header {shorten(header)}"
        )
    body: Sequence[str] = all_lines[at + 1 :]
    keep = [i for i, line in enumerate(body) if not _is_skipped(line, opts.comment)]
    if len(keep) == len(body):
        lines = list(body)
        numbers = np.arange(at + 2, at + 2 + len(body), dtype=np.int64)
    else:
        lines = [body[i] for i in keep]
        numbers = np.asarray(keep, dtype=np.int64) + at + 2
    return CsvText(where, preamble, header, at + 1, lines, numbers, separator, opts)
