"""The closed loops: simulated (:mod:`ptztrack.loop.simulated`, a camera network or one camera, the network of
it alone) and live (:mod:`ptztrack.loop.live`, against cameras that move in their own time), made of the
steps they share (:mod:`ptztrack.loop.steps`) and drawing from the episode's named streams
(:mod:`ptztrack.loop.streams`); and where work runs: the executors of an experiment's cells
(:mod:`ptztrack.loop.executors`) and a network's cameras as Ray actors (:mod:`ptztrack.loop.camera_actors`)."""
