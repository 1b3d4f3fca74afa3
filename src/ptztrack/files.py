"""Reading inputs with one-line errors, and writing outputs so that a reader never sees half of one.

Every reader of a user's file raises an :class:`InputError` (or a subclass) whose message is one
line naming the file, the field or position, and what was expected; a value is shown by
:func:`shown`, at most about 80 characters of it.
"""

import json
import math
import os
import secrets
import shutil
import stat
import zlib
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from xml.etree.ElementTree import Element

import defusedxml
import defusedxml.ElementTree as ElementTree

SHOWN_CHARACTERS = 80


class InputError(ValueError):
    """An input that cannot be used; the message is one line naming where and what was expected."""


def shown(value: object) -> str:
    """``repr(value)``, cut to about 80 characters so that an error stays one readable line.

    The value's repr is built piecewise for long containers, so a huge value is never printed whole.
    """
    if isinstance(value, list | tuple) and len(value) > SHOWN_CHARACTERS:
        text = repr(type(value)(value[:SHOWN_CHARACTERS]))
    elif isinstance(value, str | bytes) and len(value) > SHOWN_CHARACTERS:
        text = repr(value[:SHOWN_CHARACTERS])
    elif isinstance(value, dict) and len(value) > SHOWN_CHARACTERS:
        text = repr(dict(list(value.items())[:SHOWN_CHARACTERS]))
    else:
        text = repr(value)
    return text if len(text) <= SHOWN_CHARACTERS else text[: SHOWN_CHARACTERS - 3] + "..."


def read_bytes(path: str | Path, what: str, max_bytes: int, error_type: type[InputError] = InputError) -> bytes:
    """The contents of a user's file of at most ``max_bytes``; ``error_type`` naming the file otherwise.

    what : the kind of file, for the message ('ground-truth', 'calibration', ...).
    """
    path = Path(path)
    try:
        with open(path, "rb") as file:
            data = file.read(max_bytes + 1)
    except (FileNotFoundError, IsADirectoryError):
        raise _not_a_file(path, what, error_type) from None
    except OSError as error:
        raise error_type(f"{path}: cannot read the {what} file ({error.strerror or error})") from None
    if len(data) > max_bytes:
        raise error_type(f"{path}: larger than {max_bytes / 1e6:g} MB, too large for a {what} file")
    return data


def require_file(path: str | Path, what: str, error_type: type[InputError] = InputError) -> None:
    """``error_type`` naming ``path`` unless it is a file (for a file a library opens itself, a video say)."""
    if not Path(path).is_file():
        raise _not_a_file(Path(path), what, error_type)


def _not_a_file(path: Path, what: str, error_type: type[InputError]) -> InputError:
    if path.is_dir():
        return error_type(f"{path}: is a folder, expected a {what} file")
    return error_type(f"{path}: no such {what} file")


def read_text(path: str | Path, what: str, max_bytes: int, error_type: type[InputError] = InputError) -> str:
    """A user's UTF-8 text file of at most ``max_bytes`` (see :func:`read_bytes`); a ``.gz`` file is
    decompressed, to at most ``max_bytes`` too."""
    data = read_bytes(path, what, max_bytes, error_type)
    if Path(path).suffix == ".gz":
        data = _gunzip(path, data, what, max_bytes, error_type)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        raise error_type(
            f"{path}: not UTF-8 text (byte 0x{data[error.start]:02x} on line {line}); expected a {what} file"
        ) from None


def _gunzip(path, data: bytes, what: str, max_bytes: int, error_type: type[InputError]) -> bytes:
    """The content of one gzip member, refused beyond ``max_bytes`` before it is all inflated."""
    inflater = zlib.decompressobj(16 + zlib.MAX_WBITS)
    try:
        content = inflater.decompress(data, max_bytes + 1)
    except zlib.error as error:
        raise error_type(f"{path}: not gzip-compressed ({error}); expected a gzip-compressed {what} file") from None
    if len(content) > max_bytes:
        raise error_type(f"{path}: decompresses to more than {max_bytes} bytes, the limit for a {what} file")
    if not inflater.eof or inflater.unused_data:
        raise error_type(f"{path}: a truncated gzip file, or more than one member; expected one whole member")
    return content


def read_json(path: str | Path, what: str, max_bytes: int, error_type: type[InputError] = InputError) -> object:
    """A user's JSON file, strictly: NaN and Infinity, which JSON does not have, are errors."""

    def refuse(constant: str):
        raise error_type(f"{path}: {constant} is not a JSON number; expected a finite number")

    try:
        return json.loads(read_text(path, what, max_bytes, error_type), parse_constant=refuse)
    except json.JSONDecodeError as error:
        raise error_type(f"{path}: not valid JSON ({error.msg} at line {error.lineno})") from None
    except RecursionError:
        raise error_type(f"{path}: JSON nested too deeply for a {what} file") from None


def read_xml_root(path: str | Path, what: str, max_bytes: int, error_type: type[InputError] = InputError) -> Element:
    """The root element of a user's XML file, parsed by defusedxml: entities, external references and
    DTDs that could read other files, reach the network or expand without bound are errors."""
    data = read_bytes(path, what, max_bytes, error_type)
    try:
        return ElementTree.fromstring(data)
    except (ElementTree.ParseError, LookupError, ValueError) as error:
        # LookupError: an encoding Python does not know, declared in the XML header
        raise error_type(f"{path}: not valid XML ({shown(str(error))})") from None
    except defusedxml.DefusedXmlException as error:
        raise error_type(f"{path}: XML with {type(error).__name__}; expected a plain {what} file") from None


def strict_json(document: object) -> bytes:
    """``document`` as JSON that strict readers accept: NaN and infinities become ``null``.

    Numpy scalars and arrays become numbers and lists. Say why a value is undefined beside it
    (see :func:`ptztrack.evaluate.metrics.with_undefined_noted`).
    """
    return (json.dumps(_finite_or_null(document), indent=2, sort_keys=False, allow_nan=False) + "\n").encode()


def _finite_or_null(value: object) -> object:
    if isinstance(value, dict):
        return {key: _finite_or_null(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_finite_or_null(item) for item in value]
    if hasattr(value, "tolist"):
        return _finite_or_null(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(path: str | Path, document: object) -> None:
    """``document`` as strict JSON (:func:`strict_json`), written atomically (:func:`write_atomically`)."""
    write_atomically(Path(path), strict_json(document))


def write_atomically(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and a rename, so that
    a reader never sees a half-written file and an old file survives a failure."""
    path = Path(path)
    handle, temporary = open_temporary_beside(path)
    try:
        with os.fdopen(handle, "wb") as file:
            file.write(data)
        os.replace(temporary, path)
    except BaseException:
        os.unlink(temporary)
        raise


def open_temporary_beside(path: Path, suffix: str = ".tmp") -> tuple[int, Path]:
    """A new empty file beside ``path``, hidden, for what will be renamed to ``path``, and its handle open
    for writing. Its mode is the one ``path`` has, or for a new file what any Unix tool gives one
    (0666 less the umask); tempfile's would be 0600 whatever the umask."""
    path = Path(path)
    while True:
        temporary = _name_beside(path, suffix)
        try:
            handle = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
            break
        except FileExistsError:
            continue
    if path.exists():
        os.fchmod(handle, stat.S_IMODE(path.stat().st_mode))
    return handle, temporary


def _folder_beside(path: Path, suffix: str) -> Path:
    """A new empty folder beside ``path``, hidden, of the mode any Unix tool gives one (0777 less the
    umask; tempfile's would be 0700)."""
    while True:
        folder = _name_beside(path, suffix)
        try:
            folder.mkdir(0o777)
            return folder
        except FileExistsError:
            continue


def _name_beside(path: Path, suffix: str) -> Path:
    return path.absolute().parent / f".{path.name}.{secrets.token_hex(4)}{suffix}"


def check_output_file(path: Path, option: str) -> None:
    """Refuse, before any work, an output file that could not be written: ``option`` names it."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{option} {path}: is a folder, expected a file name")
    _check_writable_folder(path, option)


def check_output_folder(path: Path, option: str, overwrite: bool) -> None:
    """Refuse, before any work, a run folder that could not be written whole (see :func:`run_folder`)."""
    path = Path(path)
    here = Path.cwd().resolve()
    if path.resolve() in (here, *here.parents):
        # Replaced whole at the end, the folder a shell stands in (or one that holds it) cannot be.
        raise InputError(
            f"{option} {path}: is the current folder or holds it; expected a new folder for the run's files "
            f"(say {option} run1)"
        )
    if path.exists() and not path.is_dir():
        raise InputError(f"{option} {path}: is a file, expected a folder")
    if path.is_dir() and any(path.iterdir()) and not overwrite:
        raise InputError(f"{option} {path}: the folder is not empty (add --overwrite to replace it)")
    _check_writable_folder(path, option)


def _check_writable_folder(path: Path, option: str) -> None:
    """Refuse an output whose folder cannot take the temporary it is written through: one is made and
    removed (permissions alone do not say: root may write anywhere by them, but not into /proc)."""
    folder = path.absolute().parent
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{option} {path}: {folder} is a file, not a folder")
    if not folder.is_dir():
        raise InputError(f"{option} {path}: the folder {folder} does not exist")
    try:
        handle, probe = open_temporary_beside(path, ".probe")
    except OSError as error:
        raise InputError(f"{option} {path}: cannot write into {folder} ({error.strerror or error})") from None
    os.close(handle)
    probe.unlink()


@contextmanager
def run_folder(path: Path, overwrite: bool = False) -> Iterator[Path]:
    """A folder that appears whole or not at all: the block writes into a temporary folder beside
    ``path``, renamed into place when the block ends without an exception (an old ``path`` is then
    removed, if ``overwrite``); on any exception, Ctrl-C included, the temporary folder is removed."""
    path = Path(path)
    check_output_folder(path, "output folder", overwrite)
    temporary = _folder_beside(path, ".tmp")
    try:
        yield temporary
        if path.exists():
            retired = _folder_beside(path, ".old")
            try:
                os.replace(path, retired / path.name)
            except BaseException:
                retired.rmdir()
                raise
            os.replace(temporary, path)
            shutil.rmtree(retired)
        else:
            os.replace(temporary, path)
    finally:
        shutil.rmtree(temporary, ignore_errors=True)
