"""The Betti readers shipped with swarmtopo, and reading one from a file.

Presets (``PRESETS``, files ``swarmtopo/data/classifier-NAME.json``):

``default``
    the :class:`~swarmtopo.readers.ratio.RatioClassifier` tuned on the accuracy
    benchmark's tuning cases by ``lab/tune_accuracy.py``; ``map`` reads a log with
    status changes with it;
``trace``
    the same tuned on the benchmark's logs read as contact traces (encounters only),
    which ``map`` uses for a log without status changes (:func:`shipped_reader_for`);
``paper``
    the paper's classifier form (:class:`~swarmtopo.readers.paper.BettiClassifier`)
    trained on random environments the paper's way by ``lab/train_classifier.py``:
    ``map --paper`` and the accuracy benchmark's paper pipeline.  The paper's published
    Theta* is :func:`~swarmtopo.readers.paper.published_paper_classifier`.

A file holds one model in its one current format, named by its ``format`` key:
``swarmtopo-ratio-classifier/5`` or ``swarmtopo-classifier/1``.
"""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources
from pathlib import Path

from .._validate import check_format
from ..errors import InputError
from .._json import read_json
from ..log import EncounterLog
from .base import BettiReader
from .paper import CLASSIFIER_FORMAT, BettiClassifier
from .ratio import RATIO_FORMAT, RatioClassifier

PRESETS = ("default", "trace", "paper")
"""Readers shipped with the package (module docstring)."""
READERS = {RATIO_FORMAT: RatioClassifier, CLASSIFIER_FORMAT: BettiClassifier}
"""The reader class of each file format."""


def load_classifier(name: str | Path) -> BettiReader:
    """A shipped reader by name (``PRESETS``) or a reader from a JSON file (module docstring).

    Raises
    ------
    InputError
        Naming the file: no such preset or file, not JSON, a format other than the
        current ones (the format found and those expected), or a malformed model.
    """
    if str(name) in PRESETS:
        source = f"swarmtopo/data/classifier-{name}.json"
        obj = json.loads(_preset_text(str(name)))
    else:
        path = Path(name)
        if not path.exists():
            raise InputError(f"no such classifier: expected one of {', '.join(PRESETS)} or a JSON file",
                             file=str(path), value=str(name))
        source, obj = str(path), read_json(path)
    check_format(obj, tuple(READERS), "swarmtopo classifier", source)
    reader = READERS[obj["format"]].from_json(obj, source=source)
    if str(name) in PRESETS:
        reader.shipped_preset = str(name)
    return reader


@lru_cache(maxsize=None)
def _preset_text(name: str) -> str:
    """A shipped reader's JSON, read once per process (every map without an explicit
    reader loads one: a fresh estimator from the cached text)."""
    return resources.files("swarmtopo.data").joinpath(f"classifier-{name}.json").read_text("utf-8")


def shipped_reader_for(log: EncounterLog) -> str:
    """The preset ``map`` reads a log with: "default", fitted on logs with status
    changes, or "trace" for a log without any (a contact trace: no wall following to
    weigh), fitted on the same tuning cases read as encounters only."""
    return "default" if len(log.status_t) else "trace"
