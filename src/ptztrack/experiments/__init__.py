"""The papers' experiments, one module each: its cells, the function that runs them, its summary and its table.

* :mod:`.ptz_tables`: the PTZ paper's Tables 1-4, on the synthetic scene and on PETS 2009;
* :mod:`.registration`: the scale-invariant paper's registered live views and the closed loop on
  their poses;
* :mod:`.follow`: the robot-cameraman paper's follow camera and the one-pass (OTB) benchmark;
* :mod:`.occupancy`: the LPOM paper's occupancy maps against clustering.

:mod:`.cells` holds what they share: the :class:`~.cells.Cell` of a scenario, strategy and seed,
the run of one, and the executors' options. The face-capture experiment is in its room,
:mod:`ptztrack.facecapture.experiment`. The command line (:mod:`ptztrack.cli`) parses the options,
calls these modules and prints or writes what they return.
"""
