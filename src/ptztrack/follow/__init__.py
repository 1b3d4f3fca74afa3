"""The follow camera: one person kept at a chosen image point and size by a PTZ camera.

The robot cameraman of S. Nair, G. Panin, M. Wojtczyk, C. Lenz, T. Friedlhuber
and A. Knoll, "A multi-camera person tracking system for robotic applications
in virtual reality TV studio" (IROS 2008), on a camera that turns and zooms
instead of driving. One person is tracked in the image and the camera
is steered to frame them:

- :mod:`.parameters`: the follow camera's parameters and their defaults
  (rates per second), which the configuration maps onto;
- :mod:`.colour_model`: the target model, multi-patch hue-saturation
  histograms compared by the Bhattacharyya distance (section III-B,
  equations 2-3);
- :mod:`.motion_image`: the motion history image, the previous view carried
  into the current one by the homography of the two poses (equation 4);
- :mod:`.particle_filter`: the particle filter on the box ``(x, y, h)``,
  its loss and re-initialisation (section III-C);
- :mod:`.target`: the tracker the loop runs, a *target source* (the particle
  filter, or OpenCV's CSRT or MIL as comparators) reported as one
  ground-plane track through the output low-pass filter (section III-C6);
- :mod:`.controller`: the policy ``follow``, which moves the camera towards
  the pose that frames the person (section III-D);
- :mod:`.evaluation`: the closed loop's figures and the one-pass (OTB)
  scores of a tracker on a still video.

Nothing here reads the configuration. The scenario's ``follow`` section is
:mod:`ptztrack.config.follow`; :mod:`ptztrack.builders.follow` turns it into
these objects; the experiment (its cells, their run, its summary and tables)
is :mod:`ptztrack.experiments.follow`; the commands ``ptztrack follow`` and
``ptztrack experiment follow`` are :mod:`ptztrack.cli.follow`.
"""
