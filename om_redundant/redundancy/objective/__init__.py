"""Step 2 of the global choice: what the optimiser maximises along the paths (:mod:`.objective`,
its parts in :mod:`.terms`): joint-limit margin, obstacle clearance (:mod:`.clearance`, with
the arm's geoms in :mod:`.arm_geoms`, the pairs left to MuJoCo in :mod:`.mujoco_pairs`, a
joint-space segment's in :mod:`.segment_clearance`, the obstacles' shapes in :mod:`.shapes`)
and distance from singularities (:mod:`.singularity`)."""
