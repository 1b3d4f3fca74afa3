"""Multi-view people detection on the ground: the locus-based probabilistic occupancy map (LPOM).

T. Hu, S. Mutlu and O. Lanz, "Locus-based probabilistic occupancy map for
multi-camera people detection", ICIAP 2013, Part II, LNCS 8157, pp. 693-702:
several fixed calibrated cameras, each motion pixel's locus (the ground
positions where a person model would touch its ray) accumulated over all
views into a density on the ground, whose modes are the people. Beside it,
the "detector and clustering" baseline of the multi-view literature.

* :mod:`~ptztrack.occupancy.locus`: the person model (connected cones) and a pixel's locus;
* :mod:`~ptztrack.occupancy.lpom`: the ground grid, the locus tables, the map and its modes;
* :mod:`~ptztrack.occupancy.pom`: the probabilistic occupancy map of Fleuret et al. (TPAMI 2008) from
  foreground masks, by mean field, and :mod:`~ptztrack.occupancy.pom_rectangles`: its person rectangles
  and masks at the working resolution;
* :mod:`~ptztrack.occupancy.feet`: a candidate's position from the views' box feet near it;
* :mod:`~ptztrack.occupancy.motion_edges`: a view's evidence (motion edges, box outlines);
* :mod:`~ptztrack.occupancy.foreground`: a view's evidence from a background model (silhouettes, their edges);
* :mod:`~ptztrack.occupancy.clustering`: the baseline (box feet on the ground, clustered, blob boxes);
* :mod:`~ptztrack.occupancy.detectors`: both detectors run over a recording, frame by frame;
* :mod:`~ptztrack.occupancy.multiview`: multi-view recordings and their files;
* :mod:`~ptztrack.occupancy.room`: the paper's lab, rendered (the synthetic room) by the scene's renderer
  (:mod:`ptztrack.scene.render`), and :mod:`~ptztrack.occupancy.plaza`: PETS's far, shallow cameras over
  a rendered plaza;
* :mod:`~ptztrack.occupancy.evaluation`: scoring (MODA, MODP), threshold fitting, tracking on the ground;
* :mod:`~ptztrack.occupancy.output`: the experiment's files, pictures and video.

The modules take plain parameters. The dataset file's models live in
:mod:`ptztrack.config.dataset`, the recordings and parameters are built from
them in :mod:`ptztrack.builders.occupancy`, the experiment (its runs and
table) is :mod:`ptztrack.experiments.occupancy`, and ``ptztrack experiment
occupancy`` is :mod:`ptztrack.cli.occupancy`. The ground-plane tracker the
modes feed is :func:`ptztrack.track.tracker.update_tracks_on_ground`.
"""
