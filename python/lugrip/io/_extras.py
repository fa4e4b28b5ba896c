"""Optional packages of the ``[io]`` extra (pyarrow, mcap, rosbags), imported on first use."""

from __future__ import annotations

import importlib

#: package -> the name pip installs it by
_PIP_NAME = {"pyarrow": "pyarrow", "mcap": "mcap", "rosbags": "rosbags"}


class MissingExtraError(ImportError):
    """An optional package is not installed, or is installed but does not import. ``extra``
    names the lugrip extra that installs it (``'io'``); the message is one line saying what
    needed it and either what to install or which package failed to import and why (e.g.
    pyarrow built for numpy 2 under numpy 1.x)."""

    def __init__(self, what: str, package: str, extra: str = "io", broken: str | None = None):
        self.extra = extra
        self.package = package
        self.broken = broken
        if broken is None:
            text = (f"{what} needs the '{package}' package of the [{extra}] extra: "
                    f"pip install 'lugrip[{extra}]'")
        else:
            text = f"{what} needs '{package}', which is installed but failed to import: {broken}"
        super().__init__(text, name=package)


def _installed_version(package: str) -> str | None:
    from importlib import metadata

    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return None


def import_failure(module: str, exc: ImportError) -> str | None:
    """None when ``module``'s top-level package is simply absent; otherwise one line on why an
    installed package failed to import (its version, the exception, the numpy version when
    numpy is involved — the usual cause of a broken binary wheel)."""
    package = module.split(".")[0]
    if isinstance(exc, ModuleNotFoundError) and (exc.name or "").split(".")[0] == package:
        try:  # a submodule missing from an installed package, or the package itself absent?
            importlib.import_module(package)
        except ModuleNotFoundError as top:
            if top.name == package:
                return None
        except ImportError:
            pass
    version = _installed_version(_PIP_NAME.get(package, package))
    head = f"{package} {version}" if version else package
    text = " ".join(str(exc).split())
    if len(text) > 200:
        text = text[:197] + "..."
    why = f"{head}: {type(exc).__name__}: {text}"
    if "numpy" in text.lower() and _installed_version("numpy"):
        why += f" (numpy {_installed_version('numpy')} is installed)"
    return why


def need(module: str, what: str):
    """Import ``module`` or raise :class:`MissingExtraError` (``what``: e.g. 'reading MCAP');
    its message tells an absent package (install the extra) from an installed one that fails
    to import (the package, its version and the import error)."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        package = module.split(".")[0]
        raise MissingExtraError(what, _PIP_NAME.get(package, package),
                                broken=import_failure(module, exc)) from exc


def exc_text(exc: BaseException) -> str:
    """``Type: message`` of an exception raised by a third-party reader, for LogError texts."""
    text = str(exc).strip()
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def decode_error_text(exc: BaseException) -> str:
    """:func:`exc_text` of a message decoder's exception. rosbags before 0.11.6 checks a
    message's length with a bare ``assert`` (later versions raise "message size mismatch");
    its other asserts guard its own type tables, so a bare AssertionError while decoding one
    payload is that length check."""
    if isinstance(exc, AssertionError) and not str(exc).strip():
        return "message size mismatch: the payload does not fit its type (AssertionError)"
    return exc_text(exc)
