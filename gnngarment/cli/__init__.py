"""The ``gnngarment`` command line: every command, and the one error helper they share.

* :mod:`gnngarment.cli.commands` — the app and ``inspect``, ``prepare``, ``train``,
  ``evaluate``, ``animate``, ``benchmark-accuracy``;
* :mod:`gnngarment.cli.body` — ``body`` and ``motions``;
* :mod:`gnngarment.cli.attribute` — ``attribute``;
* :mod:`gnngarment.cli.errors` — :func:`~gnngarment.cli.errors.fail`.

The library code they drive lives in the subpackages; nothing outside ``cli`` imports
it.
"""

from gnngarment.cli.commands import app, main

__all__ = ["app", "main"]
