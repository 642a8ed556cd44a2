"""Validation against theory (sim.checks.validation): every study is a slow test, and its rows go to
the table that ``make validate`` writes to outputs/validation/table.md."""

import pytest

from sim.checks.validation import STUDIES


@pytest.mark.slow
@pytest.mark.parametrize("name", list(STUDIES))
def test_study_agrees_with_theory(name, validation_rows):
    rows = STUDIES[name]()
    validation_rows.extend(rows)
    failed = [f"{r.name}: {r.measured:.6g} vs {r.reference:.6g} ± {r.tolerance:.2g}"
              for r in rows if not r.passed]
    assert not failed, "; ".join(failed)
