"""Step 1 of the global choice: a branch's exact solutions followed along the arm angle psi
(:mod:`.probe`, :mod:`.points`), linked into solution paths through a grid (:mod:`.linking`),
and the feasible intervals of psi on them (:mod:`.intervals`)."""
