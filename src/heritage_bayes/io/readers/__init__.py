"""Readers: weather and logger files to tidy UTC DataFrames with standard column names.

One module per file format: :mod:`.csvfile` (generic CSV: loggers, exported weather),
:mod:`.knmi` (KNMI hourly station data), :mod:`.typical_year` (EPW, TMY3).

Every reader returns a :class:`pandas.DataFrame` with a tz-aware UTC
:class:`~pandas.DatetimeIndex` named ``time`` (sorted, unique, nanosecond unit) and
float columns named from :data:`heritage_bayes.io.STANDARD_COLUMNS`. Instantaneous
quantities are stamped at the reading; interval averages (irradiance) at the **end** of
their averaging interval. ``df.attrs`` documents what was read and done (see
:mod:`heritage_bayes.io`).
"""

from heritage_bayes.io.readers.csvfile import read_csv
from heritage_bayes.io.readers.knmi import read_knmi_hourly
from heritage_bayes.io.readers.typical_year import TYPICAL_YEAR, read_epw, read_tmy3

__all__ = ["TYPICAL_YEAR", "read_csv", "read_epw", "read_knmi_hourly", "read_tmy3"]
