"""Step 3 of the global choice and the tick-by-tick one: the optimiser (:mod:`.optimizer`) climbs
the runs' best starts (:mod:`.global_choice`, :mod:`.start_bounds`, :mod:`.climb` with its QP
in :mod:`.box_qp`), chooses from where the arm is (:mod:`.reachable`), tracks a moving target
(:mod:`.tracking`) and answers a :class:`~.result.RedundancyChoice` (:mod:`.result`)."""
