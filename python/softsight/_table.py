"""Table: the columns of a run as numpy arrays, a dict with a ``to_pandas()``."""

from __future__ import annotations

from typing import Any, Dict, Optional

import numpy as np

__all__ = ["Table"]


class Table(dict):
    """Columns by name, each a numpy array of one value per row, in the CSV's column order.

    A plain dict (``table["angle_deg"]``, ``list(table)``); ``summary`` holds what the run
    reported (frames, why it stopped, found rates, timings) when the table comes from a run.
    """

    def __init__(self, columns: Dict[str, np.ndarray], summary: Optional[Dict[str, Any]] = None):
        super().__init__(columns)
        self.summary = summary

    @property
    def rows(self) -> int:
        """Number of rows."""
        return len(next(iter(self.values()))) if self else 0

    def to_pandas(self):
        """The table as a pandas.DataFrame (columns in order). Needs pandas installed."""
        try:
            import pandas
        except ImportError as error:
            raise ImportError(
                "softsight Table.to_pandas() needs pandas, which is not installed "
                "(Debian: apt install python3-pandas; or pip install pandas); the table "
                "itself is a dict of numpy arrays"
            ) from error
        return pandas.DataFrame({name: column for name, column in self.items()})

    def __repr__(self) -> str:
        return f"softsight.Table({self.rows} rows: {', '.join(self)})"
