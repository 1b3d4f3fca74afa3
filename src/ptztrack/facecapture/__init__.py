"""Face capture on the Multi-Strand Tracking Graph (Melman et al., "The multi-strand graph for a PTZ
tracker", J. Math. Imaging Vis. 2018): which walker a PTZ camera zooms in on, so that captured faces
label and untangle the tracklets of a tracker that sees everybody only small.

* :mod:`~ptztrack.facecapture.roads`: the road-grid scene of the paper's simulation;
* :mod:`~ptztrack.facecapture.road_camera`: the PTZ camera over it, zoomed out or on one walker;
* :mod:`~ptztrack.facecapture.tracklets`: the tracklet tracker that builds the graph from the camera alone;
* :mod:`~ptztrack.facecapture.msg`: the graph, its vertices' auxiliary data, untangling and elimination;
* :mod:`~ptztrack.facecapture.scheduler`: the MSG scheduler and the naive one;
* :mod:`~ptztrack.facecapture.experiment`: the experiment of the paper's Figure 7, and its score M.

The command is ``ptztrack experiment msg`` (:mod:`ptztrack.cli.msg`).
"""
