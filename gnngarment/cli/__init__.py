"""The ``gnngarment`` command line: every command, and the one error helper they share.

* :mod:`gnngarment.cli.commands` — the app and ``inspect``, ``prepare``, ``train``,
  ``evaluate``, ``animate``;
* :mod:`gnngarment.cli.benchmark` — ``benchmark-accuracy`` and its experiment runner
  (:func:`~gnngarment.cli.benchmark.run_benchmark`, which drives the trainer);
* :mod:`gnngarment.cli.body` — ``body`` and ``motions``;
* :mod:`gnngarment.cli.attribute` — ``attribute``;
* :mod:`gnngarment.cli.errors` — :func:`~gnngarment.cli.errors.fail` and the option
  checks several commands share.

The library code they drive lives in the subpackages (the benchmark runner excepted: an
experiment over training and evaluation, it belongs to neither); nothing outside
``cli`` imports it.
"""

from gnngarment.cli.commands import app, main

__all__ = ["app", "main"]
