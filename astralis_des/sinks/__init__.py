"""The sinks: what a run writes, subscribed to its event stream. :mod:`.files` opens a run's
files (the event log, the summary, the Rerun recording) and registers them in
:data:`~astralis_des.simulation.outputs.OUTPUTS`; the other modules draw and export.

This package's own import is light (no module is imported here), so that a reader of
recordings (``astralis diff``, ``astralis replay``) can use :mod:`.paths`, :mod:`.blueprint`
and :mod:`.rrd_check` without importing the simulation."""
