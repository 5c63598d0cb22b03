"""Recording files as a user names them: several after one option, folders and globs.

The command line takes ``--healthy a.zip b.zip c.zip`` as well as ``--healthy a.zip
--healthy b.zip``: :func:`spread_file_options` rewrites the first form into the second
before click parses it (an option that takes files takes every word up to the next word
that starts with ``-``). :func:`expand_recordings` then turns each word into files: a file
is itself, a folder stands for the recording files directly inside it (sorted by name), a
word with ``*``, ``?`` or ``[`` is a glob pattern (for a shell that did not expand it).
"""

from __future__ import annotations

import glob
from collections.abc import Iterable, Sequence
from pathlib import Path

from .._errors import GearshotError

__all__ = ["FILE_OPTIONS", "spread_file_options", "expand_recordings", "recording_suffixes"]

#: Options that take recording files, each any number of them after one flag, by command
#: (``gearshot rig --healthy N`` is a count, not files)
FILE_OPTIONS = {"predict": frozenset({"--healthy", "--recordings"}),
                "fit": frozenset({"--healthy"}),
                "indicators": frozenset({"--baseline"})}


def spread_file_options(argv: Sequence[str]) -> list[str]:
    """``--healthy a b`` -> ``--healthy a --healthy b`` for the file options of the
    command (the first word not starting with ``-``; :data:`FILE_OPTIONS`); everything
    after ``--`` is left as it is."""
    command = next((w for w in argv if not w.startswith("-")), None)
    options = FILE_OPTIONS.get(command or "", frozenset())
    out: list[str] = []
    current: str | None = None
    first = False
    for k, word in enumerate(argv):
        if word == "--":
            out.extend(argv[k:])
            break
        if word in options:
            current, first = word, True
            out.append(word)
            continue
        if word.startswith("-") and word != "-":
            current = None
            out.append(word)
            continue
        if current is not None and not first:
            out.append(current)
        out.append(word)
        first = False
    return out


def recording_suffixes() -> set[str]:
    """File-name suffixes gearshot reads as recordings (``.zip``, ``.h5``, ``.csv``, ...)."""
    from ..io import FORMATS

    return {s if s.startswith(".") else f".{s}" for s in FORMATS}


def _in_folder(folder: Path, option: str) -> list[Path]:
    from ..io import INDEX_NAME

    suffixes = recording_suffixes()
    files = sorted(p for p in folder.iterdir()
                   if p.is_file() and p.suffix.lower() in suffixes and p.name != INDEX_NAME
                   and not p.name.startswith("."))
    if not files:
        raise GearshotError(f"{option} {str(folder)!r} is a folder without recording files "
                            f"({', '.join(sorted(suffixes))})")
    return files


def expand_recordings(items: Iterable[str | Path], option: str) -> list[Path]:
    """Files, folders and glob patterns -> recording files, in the order given.

    Parameters
    ----------
    items : iterable of str or path
        What the user typed after ``option``.
    option : str
        The option's name, quoted in errors (``"--healthy"``).

    Returns
    -------
    list of Path
        Each file once (first occurrence kept).

    Raises
    ------
    GearshotError
        A path that does not exist, a folder without recordings, or a pattern that matches
        nothing, naming ``option`` and the word.
    """
    out: list[Path] = []
    for item in items:
        text = str(item)
        path = Path(text).expanduser()
        if path.is_file():
            found = [path]
        elif path.is_dir():
            found = _in_folder(path, option)
        elif any(c in text for c in "*?["):
            found = sorted(Path(p) for p in glob.glob(str(path)) if Path(p).is_file())
            if not found:
                raise GearshotError(f"{option} {text!r} matches no file")
        else:
            raise GearshotError(f"{option}: recording {text!r} does not exist")
        out.extend(p for p in found if p not in out)
    return out
