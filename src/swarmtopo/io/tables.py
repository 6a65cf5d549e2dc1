"""The one CSV / Parquet / agent-ID parser under log folders (:mod:`.logs`) and proximity
traces (:mod:`.traces`).

Everything is vectorised: CSV and Parquet go through pyarrow's C++ readers, checks are
pyarrow compute or numpy operations, and ID columns are dictionary-encoded, so a column
of 10^6 values never becomes 10^6 Python objects.  Every problem is an
:class:`~swarmtopo.errors.InputError` naming the file, the 1-based data row (the
header not counted), the column and the value as the file writes it.

Bytes
    A file that starts with the gzip magic number is gunzipped (by content, not by
    name).  Text must be UTF-8: a UTF-16 / UTF-32 byte-order mark, or a NUL byte in the
    first 64 KiB (a spreadsheet, an archive), is refused as not text; a byte that is
    not UTF-8 is named by its line and column, ``line 3: byte 0xe9 at column 12 is not
    UTF-8 text (save the file as UTF-8)``, never as a Python escape sequence.
CSV
    A header name matches with the blanks around it ignored; a column read whose name
    appears twice is refused (a repeated name among the columns not read is fine).
Agent IDs
    Integers or text.  A CSV ID column is integer only if every ID of the columns read
    together is written as an integer (``7``, or ``7.0`` as a float column is often
    written; not ``007`` or ``-0``) and no declared ID is text; otherwise every ID is
    text.  Blanks round a CSV ID are dropped unless the ID is declared with them; two
    text IDs that differ only in those blanks are refused, never merged.
"""

from __future__ import annotations

import itertools
import re
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pcsv
import pyarrow.parquet as pq

from .._json import os_reason
from ..errors import InputError

GZIP_MAGIC = b"\x1f\x8b"
SNIFF_BYTES = 1 << 16
"""The first block of a text file, checked for binary data."""
BLOCK = 1 << 22
"""Bytes per block of a file read in blocks."""
MAX_TIME_RESOLUTION = 1e-3
"""Coarsest spacing (s) a float16 / float32 time column may have at its largest value:
beyond it the file's times were already rounded when written (float32 epoch seconds are
128 s apart), so they are refused rather than read as fewer, shifted times."""

_OTHER_ENCODINGS = ((b"\xff\xfe\x00\x00", "UTF-32"), (b"\x00\x00\xfe\xff", "UTF-32"),
                    (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16"))
_INTEGER_TEXT = r"^(0|-?[1-9][0-9]*)(\.0+)?$"
"""An ID written as an integer: plain (not 017, not -0: those stay text), or with a zero
fraction, as a float column is often written (12.0 is agent 12, as in a Parquet float column)."""


# -- files and bytes -----------------------------------------------------------------------
def existing_file(path, what: str = "file") -> Path:
    """``path`` as a Path if it is a regular file; else InputError (``what`` names the
    missing file: ``trace file not found``)."""
    path = Path(path)
    if path.is_dir():
        raise InputError("is a folder, not a file", file=str(path))
    if path.exists() and not path.is_file():
        raise InputError("is not a regular file (a pipe, socket or device: it is read more than once, so save it "
                         "to a file first)", file=str(path))
    if not path.is_file():
        raise InputError(f"{what} not found", file=str(path))
    return path


def is_gzip(path: Path) -> bool:
    """Whether the file starts with the gzip magic number (OSError if it cannot be read)."""
    with open(path, "rb") as f:
        return f.read(2) == GZIP_MAGIC


def open_bytes(path: Path) -> pa.NativeFile:
    """The file's bytes as a pyarrow stream: gunzipped if it is gzip, by content (a
    ``.gz`` file that is not gzip is read as it is); other compressions (``.bz2``,
    ``.zst``, ...) by name, as pyarrow detects them."""
    try:
        compression = "gzip" if is_gzip(path) else None if path.name.endswith(".gz") else "detect"
        return pa.input_stream(str(path), compression=compression)
    except OSError as exc:
        raise read_error(path, exc) from None


def read_error(path: Path, exc: Exception) -> InputError:
    """The one-line error of a file the system refuses to read or a broken gzip stream."""
    reason = os_reason(exc) if isinstance(exc, OSError) else str(exc)
    try:
        gzipped = is_gzip(path)
    except OSError:
        gzipped = False
    return InputError(f"{'cannot decompress the gzip file' if gzipped else 'cannot read file'} ({reason})",
                      file=str(path))


def blocks(path: Path, size: int = BLOCK):
    """The file's bytes (gunzipped) in consecutive blocks of ``size``; read errors named."""
    try:
        with open_bytes(path) as f:
            while block := f.read(size):
                yield block
    except (OSError, pa.ArrowInvalid) as exc:  # a truncated or corrupt gzip stream too
        raise read_error(path, exc) from None


# -- text ------------------------------------------------------------------------------------
def refuse_binary(path: Path, head: bytes) -> None:
    """InputError naming ``path`` if ``head``, the first block of a text file, starts with
    the byte-order mark of UTF-16 / UTF-32 or holds a NUL byte (binary data: a
    spreadsheet, an archive, UTF-16 without a byte-order mark)."""
    for bom, encoding in _OTHER_ENCODINGS:
        if head.startswith(bom):
            raise InputError(f"not UTF-8 text: it starts with the byte-order mark of {encoding}; save it as UTF-8",
                             file=str(path))
    nul = head.find(b"\0")
    if nul >= 0:
        line = head.count(b"\n", 0, nul) + 1
        raise InputError(f"binary data, not text: line {line} holds a NUL byte (save the table as UTF-8 CSV)",
                         file=str(path))


def check_text(path: Path) -> None:
    """Refuse a file that is binary (:func:`refuse_binary`) or not UTF-8 throughout."""
    chunks = blocks(path)
    head = next(chunks, b"")
    refuse_binary(path, head[:SNIFF_BYTES])
    problem = utf8_problem(itertools.chain([head], chunks))
    if problem:
        raise InputError(problem, file=str(path))


def utf8_problem(chunks) -> str | None:
    """Where the bytes ``chunks`` (consecutive blocks of a file) stop being UTF-8 text:
    ``line L: byte 0xXX at column C is not UTF-8 text (save the file as UTF-8)``, the
    line and column (in characters) 1-based; None if they are UTF-8 throughout."""
    line, column, tail = 1, 1, b""
    for block in itertools.chain(chunks, [b""]):  # b"": the end, where a cut character is an error
        data = tail + block
        try:
            text, tail = data.decode("utf-8"), b""
        except UnicodeDecodeError as exc:
            if block and exc.reason == "unexpected end of data":  # a character cut by the block's end
                text, tail = data[:exc.start].decode("utf-8"), data[exc.start:]
            else:
                line, column = _advance(line, column, data[:exc.start].decode("utf-8"))
                return f"line {line}: {_bad_byte(data[exc.start], f'column {column}')}"
        line, column = _advance(line, column, text)
    return None


def _advance(line: int, column: int, text: str) -> tuple[int, int]:
    """(line, column) after ``text``, from (line, column) before it."""
    breaks = text.count("\n")
    if breaks:
        return line + breaks, len(text) - text.rfind("\n")
    return line, column + len(text)


def not_utf8_reason(raw: bytes, where: str = "column") -> str:
    """The message for ``raw`` (one line, or one value if ``where`` is ``"value"``),
    naming its first byte that is not UTF-8 and where it stands."""
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        k = len(raw[:exc.start].decode("utf-8")) + 1
        return _bad_byte(raw[exc.start], f"column {k}" if where == "column" else f"character {k} of the value")
    raise ValueError("the bytes are UTF-8 text")


def _bad_byte(byte: int, where: str) -> str:
    return f"byte 0x{byte:02x} at {where} is not UTF-8 text (save the file as UTF-8)"


def not_utf8(col: pa.Array) -> np.ndarray:
    """Mask of the binary values that are not UTF-8: one cast if all are, else each
    value of the block decoded once (a file saved in Latin-1 costs O(n), not O(n^2))."""
    try:
        pc.cast(col, pa.large_string())
        return np.zeros(len(col), bool)
    except pa.ArrowInvalid:
        return np.fromiter((v is not None and not _decodes(v) for v in col.to_pylist()), bool, count=len(col))


def _decodes(value: bytes) -> bool:
    try:
        value.decode("utf-8")
        return True
    except UnicodeDecodeError:
        return False


# -- CSV ---------------------------------------------------------------------------------------
def csv_header(path: Path) -> list[str]:
    """The column names of a CSV file as written (binary or non-UTF-8 headers refused)."""
    head = next(blocks(path, SNIFF_BYTES), b"")
    refuse_binary(path, head)
    # rows the parser cannot split are skipped when reading the header -- the read of the
    # data reports them -- unless they may not be UTF-8: pyarrow fails to hand those over
    try:
        head.decode("utf-8")
        clean = True
    except UnicodeDecodeError as exc:
        clean = exc.reason == "unexpected end of data" and len(head) == SNIFF_BYTES
    parse = pcsv.ParseOptions(invalid_row_handler=(lambda row: "skip") if clean else None)
    try:
        with pcsv.open_csv(open_bytes(path), read_options=pcsv.ReadOptions(block_size=SNIFF_BYTES),
                           parse_options=parse) as reader:
            return reader.schema.names
    except UnicodeDecodeError:
        raise InputError(utf8_problem(blocks(path)) or "not UTF-8 text", file=str(path)) from None
    except pa.ArrowInvalid as exc:
        raise csv_problem(path, exc) from None
    except OSError as exc:
        raise read_error(path, exc) from None


def find_columns(names: list[str], required, path: Path, *, optional=(), every: bool = False) -> dict[str, str]:
    """``{name: name as written}`` of a file's columns ``names``, matched with the blanks
    round a name ignored (the first of a repeated name).

    A ``required`` or ``optional`` column (any column if ``every``) whose name appears
    twice, or a missing ``required`` one, is refused naming the columns found.
    """
    by_name: dict[str, str] = {}
    for raw in names:
        name = raw.strip()
        if name in by_name and (every or name in required or name in optional):
            raise InputError("column appears twice", file=str(path), column=name)
        by_name.setdefault(name, raw)  # a name repeated among the ignored columns is never read
    missing = [c for c in required if c not in by_name]
    if missing:
        raise InputError(f"missing column '{missing[0]}'; found columns: {', '.join(map(repr, by_name)) or 'none'}",
                         file=str(path), column=missing[0])
    return by_name


def read_csv(path: Path, columns: list[str], text: set[str]) -> pa.Table:
    """The ``columns`` of a CSV file, multi-threaded; ``text`` ones as strings, others
    inferred.  Blank lines are read as rows (of empty strings), so that rows are numbered
    as the file's data lines."""
    convert = pcsv.ConvertOptions(include_columns=columns, column_types={c: pa.string() for c in text},
                                  strings_can_be_null=False)
    try:
        return pcsv.read_csv(open_bytes(path), parse_options=pcsv.ParseOptions(ignore_empty_lines=False),
                             convert_options=convert)
    except pa.ArrowInvalid as exc:
        if "invalid UTF8" in str(exc):
            raise _not_utf8_value(path, columns, text) from None
        raise csv_problem(path, exc) from None
    except OSError as exc:
        raise read_error(path, exc) from None


def _not_utf8_value(path: Path, columns: list[str], text: set[str]) -> InputError:
    """The error for a text column that is not UTF-8, at its first bad row; the value is
    quoted with the bad bytes shown as U+FFFD."""
    try:
        raw = pcsv.read_csv(open_bytes(path), parse_options=pcsv.ParseOptions(ignore_empty_lines=False),
                            convert_options=pcsv.ConvertOptions(
            include_columns=columns, column_types={c: pa.binary() for c in text}))
    except pa.ArrowInvalid as exc:  # a row that does not parse either
        return csv_problem(path, exc)
    bad = []
    for name in columns:
        if name in text:
            col = raw.column(name).combine_chunks()
            try:
                col.cast(pa.string())
            except pa.ArrowInvalid:
                i = first_uncastable(col, pa.string())
                bad.append((i, name, col[i].as_py()))
    if not bad:
        return InputError(utf8_problem(blocks(path)) or "not UTF-8 text", file=str(path))
    i, name, value = min(bad)
    return InputError(not_utf8_reason(value, "value"), file=str(path), row=i + 1, column=name.strip(),
                      value=value.decode("utf-8", "replace"))


def csv_problem(path: Path, exc: Exception) -> InputError:
    """pyarrow's parse error, with the 1-based data row and its text found by a
    single-threaded re-read; or, in a file that is not UTF-8 throughout (pyarrow cannot
    hand such a row to Python), the first byte that is not."""
    not_utf8_text = utf8_problem(blocks(path))
    if not_utf8_text:
        return InputError(not_utf8_text, file=str(path))
    bad = []

    def record(row):
        bad.append(row)
        return "error"

    try:
        pcsv.read_csv(open_bytes(path), read_options=pcsv.ReadOptions(use_threads=False),
                      parse_options=pcsv.ParseOptions(invalid_row_handler=record))
    except (pa.ArrowInvalid, OSError):
        pass
    if bad and bad[0].number is not None:  # number counts the header as row 1
        return InputError(f"cannot parse CSV (expected {bad[0].expected_columns} columns, found "
                          f"{bad[0].actual_columns})", file=str(path), row=bad[0].number - 1, value=bad[0].text)
    # pyarrow >= 26.0.1 prefixes its own "Row #N: " (a file line, header included): dropped, as
    # every message here counts data rows
    reason = re.sub(r"^Row #\d+: ", "", str(exc).removeprefix("CSV parse error: "))
    return InputError(f"cannot parse CSV ({reason})", file=str(path))


def trim(col) -> pa.Array:
    """Text trimmed of surrounding blanks, nulls as empty text."""
    if isinstance(col, pa.ChunkedArray):
        col = col.combine_chunks()
    return pc.utf8_trim_whitespace(col.fill_null(""))


def blank_rows(columns) -> np.ndarray:
    """Rows whose every column (trimmed text) is empty: a CSV blank line.  A column that
    is not text is never blank."""
    blank = None
    for col in columns:
        if not pa.types.is_string(col.type):
            return np.zeros(len(col), bool)
        empty = pc.equal(pc.utf8_length(col), 0).to_numpy(zero_copy_only=False)
        blank = empty if blank is None else blank & empty
    return blank


# -- Parquet -----------------------------------------------------------------------------------
def parquet_file(path: Path) -> pq.ParquetFile:
    """An open Parquet file; one that is not Parquet is refused naming it."""
    try:
        return pq.ParquetFile(path)
    except (pa.ArrowException, OSError) as exc:
        raise InputError(f"cannot read Parquet file ({exc})", file=str(path)) from None


def read_parquet(pf: pq.ParquetFile, columns: list[str], path: Path) -> pa.Table:
    """The ``columns`` of an open Parquet file, multi-threaded."""
    try:
        return pf.read(columns=columns)
    except (pa.ArrowException, OSError) as exc:
        raise InputError(f"cannot read Parquet file ({exc})", file=str(path)) from None


# -- numbers -----------------------------------------------------------------------------------
def number_column(col: pa.Array, path: Path, name: str, what: str, rows: np.ndarray) -> np.ndarray:
    """float64 column; text is parsed, and the first bad value is located exactly (at its
    source row: ``rows[i]`` is the 1-based data row of value ``i``).  ``what`` names the
    quantity (``"time"`` also refuses coarse float times, :func:`coarse_time`)."""
    kind = col.type
    if pa.types.is_string(kind) or pa.types.is_large_string(kind):
        try:
            col = pc.cast(col, pa.float64())
        except pa.ArrowInvalid:
            i = first_uncastable(col, pa.float64())
            value = col[i].as_py()
            problem = f"{what} is missing" if value == "" else f"{what} is not a number"
            raise InputError(problem, file=str(path), row=int(rows[i]), column=name, value=value) from None
    elif pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_decimal(kind):
        coarse = coarse_time(col) if what == "time" else None
        if coarse is not None:
            i, problem = coarse
            raise InputError(problem, file=str(path), row=int(rows[i]), column=name, value=col[i].as_py())
        col = pc.cast(col, pa.float64(), safe=False)  # integers beyond 2^53 round; times that large are refused
    elif pa.types.is_null(kind) and len(col) == 0:
        col = pa.array([], pa.float64())
    else:
        raise InputError(f"{what} must be a number, not {kind}", file=str(path),
                         row=int(rows[0]) if len(rows) else None, column=name,
                         value=col[0].as_py() if len(col) else None)
    if col.null_count:
        i = int(np.argmax(col.is_null().to_numpy(zero_copy_only=False)))
        raise InputError(f"{what} is missing", file=str(path), row=int(rows[i]), column=name)
    return col.to_numpy(zero_copy_only=False)


def coarse_time(col: pa.Array) -> tuple[int, str] | None:
    """(index of the largest time, message) if ``col`` is a float16 / float32 column whose
    spacing at its largest finite value exceeds ``MAX_TIME_RESOLUTION``; else None (the
    column is read as float64, exactly)."""
    if not (pa.types.is_float16(col.type) or pa.types.is_float32(col.type)):
        return None
    values = col.fill_null(0).to_numpy(zero_copy_only=False)
    finite = np.isfinite(values)
    if not finite.any():
        return None
    i = int(np.argmax(np.where(finite, np.abs(values), -1)))
    spacing = float(np.spacing(np.abs(values[i])))
    if spacing <= MAX_TIME_RESOLUTION:
        return None
    return i, (f"a {col.type} time column tells times apart only to {spacing:g} s at its largest value (the "
               f"file's times were rounded when written); write them as float64 or integers")


def first_uncastable(col: pa.Array, to_type) -> int:
    """Index of the first value that does not cast; bisection, so O(n) vectorised work."""
    lo, hi = 0, len(col)  # invariant: the first bad value lies in col[lo:hi]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        try:
            pc.cast(col.slice(lo, mid - lo), to_type)
        except pa.ArrowInvalid:
            hi = mid
        else:
            lo = mid
    return lo


# -- agent IDs -----------------------------------------------------------------------------------
class IdColumn(NamedTuple):
    """An ID column as read: its values, file, column name, the 1-based data row of each
    value, and whether it comes from CSV (text without types, blanks round it dropped)."""

    values: pa.Array
    file: Path
    name: str
    rows: np.ndarray
    csv: bool


def id_columns(columns: list[IdColumn], *, declared=None) -> list:
    """Give ID columns read together (a log folder's, a trace's) one kind: int64 numpy
    arrays, or pyarrow text.

    Integer if every column is integer-typed (floats are left to the log's integrality
    check) or, in CSV, holds only IDs written as integers (:func:`integer_ids`), and
    ``declared`` (meta's ``agent_ids``) holds no text.  Text columns of a Parquet file
    are text whatever they hold; a column that cannot be read as text (a list, a
    struct) is refused.  A CSV ID is trimmed of surrounding blanks unless ``declared``
    lists it as written (so that a log's padded text IDs read back exactly); two text
    IDs that trimming would merge are refused.
    """
    declared = list(declared or [])
    kept = pa.array([str(v) for v in declared], pa.string())
    checked = []  # (column, is numeric, from a CSV file)
    written = []  # CSV columns as written
    for column in columns:
        col = column.values
        if col.null_count:
            i = int(np.argmax(col.is_null().to_numpy(zero_copy_only=False)))
            raise InputError("agent ID is missing", file=str(column.file), row=int(column.rows[i]),
                             column=column.name)
        numeric = pa.types.is_integer(col.type) or pa.types.is_floating(col.type)
        if not numeric:
            try:
                col = pc.cast(col, pa.string())
            except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
                raise InputError(f"agent IDs must be integers or text, not {col.type}", file=str(column.file),
                                 column=column.name) from None
        if column.csv:
            written.append(column._replace(values=col))
            col = trimmed_ids(col, kept)
        checked.append((col, numeric, column.csv))
    declared_text = any(isinstance(v, str) for v in declared)
    if not declared_text and all(numeric or csv for _, numeric, csv in checked):  # CSV has no types
        texts = integer_ids([col for col, numeric, _ in checked if not numeric])
        if texts is not None:
            texts = iter(texts)
            try:
                ints = [col if pa.types.is_floating(col.type) else pc.cast(col, pa.int64()) if numeric else next(texts)
                        for col, numeric, _ in checked]
            except pa.ArrowInvalid:  # an unsigned integer beyond int64: every ID is text
                pass
            else:
                return [col.to_numpy(zero_copy_only=False) for col in ints]
    refuse_merged_by_trimming(written, kept)
    return [pc.cast(col, pa.string()) if numeric else col for col, numeric, _ in checked]


def trimmed_ids(col: pa.Array, kept: pa.Array) -> pa.Array:
    """CSV ID text trimmed of surrounding blanks, except the IDs in ``kept`` (as written)."""
    return pc.if_else(pc.is_in(col, value_set=kept), col, pc.utf8_trim_whitespace(col))


def refuse_merged_by_trimming(written: list[IdColumn], kept: pa.Array) -> None:
    """InputError at the first padded spelling of an ID that another spelling in the CSV
    ID columns ``written`` also trims to: trimming would merge two distinct text IDs."""
    if not written:
        return
    spellings = pc.unique(pa.concat_arrays([column.values for column in written]))
    ids = trimmed_ids(spellings, kept)
    enc = pc.dictionary_encode(ids)
    if len(enc.dictionary) == len(spellings):
        return
    index = enc.indices.to_numpy(zero_copy_only=False)
    merged = np.bincount(index, minlength=len(enc.dictionary))[index] > 1
    padded = spellings.filter(pa.array(merged & ~pc.equal(spellings, ids).to_numpy(zero_copy_only=False)))
    for col, path, name, rows, _ in written:
        hit = pc.is_in(col, value_set=padded).to_numpy(zero_copy_only=False)
        if hit.any():
            i = int(np.argmax(hit))
            trimmed = col[i].as_py().strip()
            raise InputError(f"agent ID differs from the ID {trimmed!r} only in the blanks around it, which a CSV "
                             f"field drops: the two would merge into one agent (spell each agent one way, or use "
                             f"Parquet, which keeps blanks)", file=str(path), row=int(rows[i]), column=name,
                             value=col[i].as_py())


def integer_ids(columns: list[pa.Array]) -> list[pa.Array] | None:
    """Text ID columns as int64, if every ID is written as an integer (``12``, or ``12.0``
    for the same agent; not ``012`` or ``-0``) and fits int64; else None.  Exact: the
    integer part is parsed as text, never through a float.  The text work is done once per
    distinct ID."""
    encoded = [pc.dictionary_encode(col) for col in columns]
    if not all(pc.all(pc.match_substring_regex(enc.dictionary, _INTEGER_TEXT)).as_py() is not False
               for enc in encoded):
        return None
    try:
        return [pc.take(pc.cast(pc.replace_substring_regex(enc.dictionary, r"\.0+$", ""), pa.int64()), enc.indices)
                for enc in encoded]
    except pa.ArrowInvalid:  # beyond int64: every ID is text
        return None
