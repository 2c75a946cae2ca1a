"""igi's log reaches Python's logging, logger "igi", at the level igi gave it."""

import logging

import igi
from igi import _igi


def test_messages_reach_the_igi_logger(caplog):
    caplog.set_level(logging.DEBUG, logger="igi")
    _igi._log(logging.WARNING, "routed")
    records = [r for r in caplog.records if r.name == "igi" and r.getMessage() == "routed"]
    assert len(records) == 1 and records[0].levelno == logging.WARNING


def test_set_log_level_filters_in_igi(caplog):
    caplog.set_level(logging.DEBUG, logger="igi")
    igi.set_log_level(logging.WARNING)
    try:
        _igi._log(logging.INFO, "dropped")
        assert not [r for r in caplog.records if r.getMessage() == "dropped"]
    finally:
        igi.set_log_level(logging.INFO)
