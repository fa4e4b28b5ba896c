"""Optional packages of the ``[io]`` extra (pyarrow, mcap, rosbags), imported on first use."""

from __future__ import annotations

import importlib

#: package -> the name pip installs it by
_PIP_NAME = {"pyarrow": "pyarrow", "mcap": "mcap", "rosbags": "rosbags"}


class MissingExtraError(ImportError):
    """An optional package is not installed. ``extra`` names the lugrip extra that installs
    it (``'io'``); the message is one line saying what needed it and what to install."""

    def __init__(self, what: str, package: str, extra: str = "io"):
        self.extra = extra
        self.package = package
        super().__init__(f"{what} needs the '{package}' package of the [{extra}] extra: "
                         f"pip install 'lugrip[{extra}]'", name=package)


def need(module: str, what: str):
    """Import ``module`` or raise :class:`MissingExtraError` (``what``: e.g. 'reading MCAP')."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        package = module.split(".")[0]
        raise MissingExtraError(what, _PIP_NAME.get(package, package)) from exc


def exc_text(exc: BaseException) -> str:
    """``Type: message`` of an exception raised by a third-party reader, for LogError texts."""
    text = str(exc).strip()
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__
