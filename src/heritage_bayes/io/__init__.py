"""Reading the world: weather and logger files to tidy UTC DataFrames, and alignment.

Conventions
-----------
**Columns.** Standard names and units (:data:`STANDARD_COLUMNS`): ``Te`` [°C], ``RHe``
[%], ``ghi``, ``dni``, ``dhi`` [W/m²], ``Ti`` [°C], ``RHi`` [%], ``Pe``, ``Pi`` [Pa]
(derived with :func:`add_vapour_pressure`), ``Tdew`` [°C].

**Time.** Every reader returns a tz-aware **UTC** ``DatetimeIndex`` named ``time``,
sorted and unique. Instantaneous quantities (temperature and RH readings) are stamped at
the instant of the reading. Interval averages or sums (irradiance) are stamped at the
**end** of their averaging interval, the meteorological convention of KNMI ``HH``, EPW
and TMY3. ``df.attrs`` says which is which:

``attrs["averaged"]``
    tuple of the interval-average columns, e.g. ``("ghi", "dni", "dhi")``;
``attrs["interval"]``
    length of the averaging interval, e.g. ``"1h"``;
``attrs["source"]``, ``attrs["format"]``, ``attrs["timezone"]``, ``attrs["units"]``
    provenance;
``attrs["dropped"]``, ``attrs["clipped"]``
    counts of rows or values the reader removed or changed, by reason;
``attrs["irradiance_source"]``
    ``"measured"`` or how the irradiance was obtained (e.g. a clear-sky proxy).

**Local clocks.** Fixed offsets (``"UTC+2"``) are exact. For a clock with daylight-saving
time (``"Europe/Copenhagen"``): a repeated autumn hour is resolved by file order when the
file holds both passes; when it holds only one, those rows are dropped and counted
(``attrs["dropped"]["ambiguous_dst"]``); stamps inside the skipped spring hour are dropped
and counted (``nonexistent_dst``); otherwise the spring hour is simply a one-hour gap.
Nothing is silently duplicated: other duplicate timestamps are an error unless a policy
is chosen (``duplicates=``).

**Grid.** :func:`align` puts inputs (weather) and measurements (outputs) on one regular UTC
grid matching the simulator's zero-order hold (``x[k+1] = Ad x[k] + Bd u[k]``, ``u[k]``
held over ``[t_k, t_k + step)``): an input at row ``t_k`` is the mean over
``[t_k, t_k + step)``; a measurement at row ``t_k`` is the instantaneous value at ``t_k``.
:attr:`Aligned.slopes` adds each instantaneous input's change over the row,
``u(t_k + step) - u(t_k)`` (zero for interval averages): with it the simulator holds a
reading linear between samples (first-order hold) and an average constant over its
interval, each exactly (``data.input_hold: exact``).
"""

from heritage_bayes.io._common import STANDARD_COLUMNS, parse_timezone
from heritage_bayes.io.align import Aligned, AlignmentReport, Gap, align
from heritage_bayes.io.derive import add_vapour_pressure
from heritage_bayes.io.readers import TYPICAL_YEAR, read_csv, read_epw, read_knmi_hourly, read_tmy3

__all__ = [
    "STANDARD_COLUMNS",
    "TYPICAL_YEAR",
    "Aligned",
    "AlignmentReport",
    "Gap",
    "add_vapour_pressure",
    "align",
    "parse_timezone",
    "read_csv",
    "read_epw",
    "read_knmi_hourly",
    "read_tmy3",
]
