"""What every column of solutions.csv, sweep.csv, events.csv, barriers.csv, folds.csv,
regions.csv and the design CSV means, and every solve count (written into each run)."""

from __future__ import annotations

SOLUTIONS = {
    "solution_id": "1, 2, ...: physical rows first, then other real roots, then complex ones; "
    "within each group by angle",
    "gamma1_deg, gamma2_deg": "the angles (deg) in [0, 360); for a non-real solution the real "
    "part of the complex angle gamma = -i log(c + i s)",
    "d1, d2": "spring lengths (m): the solver's signed length variable for a spring with L0 > 0, "
    "the geometric length |P| for a zero-free-length spring",
    "is_real": "every variable has |Im| < 1e-8 relative to 1 + |Re| (for a singular root "
    "10 sqrt(tracking accuracy), at most 1e-4)",
    "max_imag": "the largest |Im| / (1 + |Re|) over the variables: how far from real",
    "physical": "real, both spring lengths > 0, and not a zero-length artefact",
    "stable": "physical, not singular, and the Hessian of the energy V in (gamma1, gamma2) is "
    "positive definite: a strict local minimum of V",
    "residual": "max |f_i| of the polynomial system at the reported point after Newton "
    "refinement, in units of L3 and max(k1, k2)",
    "condition_number": "the solver's estimate (1/rco for PHCpack), the largest over the "
    "endpoints merged into this row; infinite for closed-form d = 0 artefacts",
    "multiplicity": "how many path endpoints reached this solution",
    "reason": "why a row is not physical: complex, negative_d (an equilibrium of a mechanism "
    "with free length -L0) or zero_length_spring (a d = 0 artefact: a spring with L0 > 0 has "
    "|d| < 1e-5 L3, its ends coincide and its force direction is undefined); empty if physical",
    "singular": "jacobian_condition > 1e12, or several path endpoints at this solution",
    "jacobian_condition": "our condition number of the Jacobian at the refined point (units of "
    "L3 and max(k)): ordinary roots 1e1-1e7, large near a fold, 1e14+ when exactly singular",
    "kind": "physical rows: min, saddle or max of V, or degenerate (a Hessian eigenvalue within "
    "1e-9 k L3^2 of 0)",
    "energy": "V = 1/2 k1 (d1 - L01)^2 + 1/2 k2 (d2 - L02)^2 (J); NaN unless physical",
    "hess_eig1, hess_eig2": "eigenvalues of the Hessian of V in (gamma1, gamma2), ascending "
    "(J/rad^2); NaN unless physical",
    "spring1_force, spring2_force": "f_i = k_i (d_i - L0i), tension > 0 (N); NaN unless physical",
    "rod_force": "f3 of eq. (5), tension > 0: negative means the rod is in compression (N)",
    "tensegrity": "both springs in tension and the rod in compression",
    "paper_stable": "the paper's criterion, for comparison only: every eigenvalue of the Jacobian "
    "of its tan-half equations has a negative real part (not a mechanical criterion)",
    "gamma1_imag_deg, gamma2_imag_deg": "imaginary parts of the complex angles (0 for real rows)",
    "paths": "the path numbers that ended at this solution (-1: computed in closed form; on "
    'the real route, `route="real"`, no path: the search\'s number of the root, from 0)',
    "<var>_re, <var>_im": "the solver's variables (c1, s1, c2, s2, and d1, d2 where a spring has "
    "L0 > 0) as computed",
    "certified": "after `--certify` / cb.certify only: a unique solution of the polynomial system "
    "is proved (Krawczyk, ball arithmetic) in the box around this row, real if the row is real, "
    "non-real if not; singular rows (double roots) cannot be",
    "certified_radius": "after `--certify` only: the half-width of that box in every variable, in "
    "units of L3 for d (NaN where not certified); for a framework the largest half-width, in its "
    "normalised units (each variable's relative to its own size), and complex rows not tried",
}

SWEEP = {
    "point": "index of the sweep point (grid order; the second parameter varies fastest)",
    "<param>, <param2>": "the swept parameter values at this point (columns named by them)",
    "solutions.csv columns": "as in solutions.csv, one row per finite solution of the point",
    "method": "how the point was solved: parameter homotopy (+ adaptive retrack), second start, "
    "ab initio, or the cli engine",
    "lost_paths": "paths that failed at this point (empty where the engine does not say)",
    "status": "ok, or incomplete when the point's Morse count failed, a path was lost, or (with "
    "--certify) its proof was not complete",
    "certificate, certify_seconds": "with --certify: the point's certificate status (proved, "
    "undecided, contradiction) and what it cost",
    "branch": "1-D sweeps: which branch the row belongs to (secant prediction + one-to-one "
    "assignment over all finite solutions, so branches continue through folds)",
}

EVENTS = {
    "kind": "fold, pitchfork, stability_change or physical_change",
    "branches": "the branch ids involved (a+b for a fold)",
    "<param>": "the refined parameter value of the event",
    "gamma1_deg, gamma2_deg": "the configuration at the event",
    "refined": "whether Newton (folds) or bisection (other events) converged",
    "residual": "fold: max |F|, |J v| relative to the coefficients; stability change: "
    "|eigenvalue| / max |eigenvalue|; physical change: the larger of |d_i| and the relative |F|",
    "bracket": "accuracy of the value: the last Newton step or the bisection bracket width",
    "description": "what happens, in words",
    "lo, hi": "the sweep points on either side",
    "variables, x, null_vector": "the point in solver variables and, for folds, the null vector",
}

FOLDS = {
    "L01, L02": "the free lengths (m) of the fold point (either may be negative: not physical)",
    "gamma1_deg, gamma2_deg": "the equilibrium's angles (deg) in [0, 360)",
    "d1, d2": "the spring lengths (m)",
    "physical": "both free lengths >= 0, and not zero_length",
    "family": "relaxed (both springs at their free length: L0 = d) or tensioned (the pose on the "
    "parallel curve with free lengths on its line)",
    "curve_id": "the connected piece of the fold set the point belongs to (points of one family "
    "within 1 deg in pose and 0.05 L3 in free length are joined)",
    "kind": "fold; cusp: where a fold curve stops and turns back (a degenerate fold; its "
    "curve_id is -1); or zero_length: a spring shorter than the solutions' zero-length rule "
    "(1e-5 L3), where V is not smooth and a fold curve ends (not physical)",
    "hess_eig_min": "the Hessian eigenvalue nearest zero (J/rad^2): 0 at a fold, up to rounding",
}

REGIONS = {
    "L01, L02": "a grid point (m): the window's ends and the evenly spaced values between, "
    "each the double nearest its exact decimal value (0 to 14 in 41 points gives 2.1, not "
    "2.0999999999999996)",
    "physical": "the number of physical equilibria there (a direct solve)",
    "stable": "the number of stable equilibria there",
}

FRAMEWORK_FOLDS = {
    "<x>, <y>": "the two map parameters (named as in the file, its units) at the point",
    "framework solutions.csv columns": "the pose, positions, link lengths and tensions and the "
    "energy of the equilibrium at the point, named as in the framework's solutions.csv",
    "curve_id": "the traced curve the point lies on (a curve is split where it stops being "
    "physical); its rows in order of `arc` form a polyline",
    "arc": "distance along the curve's image in the plane from its first point, in units of the "
    "window's diagonal",
    "kind": "fold (the reduced Hessian singular: two equilibria meet), cusp (where a fold curve's "
    "image turns back; confirmed by null_cubic), cable_switch (a taut cable exactly at its "
    "free length: the equilibrium passes between taut sets), or pitchfork (maps by continuation: "
    "the Hessian singular with the parameters' pull on the equilibria orthogonal to its null "
    "direction, so the branch passes instead of turning: a symmetric state meets the mirror "
    "pair it splits into)",
    "physical": "the equilibrium at the point is physical (real, lengths > 0, taut set "
    "consistent); a map keeps only these, inside its window",
    "changes_stable_count": "crossing the curve here changes the number of stable equilibria (a "
    "minimum meets an index-1 saddle, or a stable taut branch ends at a cable switch); false for "
    "two maxima, or a saddle and a maximum, meeting",
    "taut": "the taut set of cables whose system the point solves (none: no cable taut)",
    "null_cubic": "fold and cusp rows: |w . F_XX[v, v]| / |F_XX[v, v]| (v, w the unit right and "
    "left null vectors of the equilibrium Jacobian J_X F, F_XX[v, v] by central differences): "
    "the energy's cubic term along the null direction, 0 at a cusp; empty at cable switches. "
    "Curves traced in chart angles (frameworks on the real route): |v . (d/de H(theta + e v)) "
    "v| / max(1, |H|), H the Hessian in chart angles, v its unit null vector",
}

FRAMEWORK_REGIONS = {
    "<x>, <y>": "a grid point of a framework's map, in the units of its file (the two map "
    "parameters, named as in the file): the window's ends and the evenly spaced values between, "
    "each the double nearest its exact decimal value",
    "physical": "the number of physical equilibria there (every taut set; the 2-D sweep's point)",
    "stable": "the number of stable equilibria there",
}

DESIGN = {
    "gamma1_deg, gamma2_deg": "the pose asked for (deg), in [0, 360)",
    "L01, L02": "the free lengths (m) holding the pose in equilibrium (may be negative: then not "
    "physical)",
    "d1, d2": "the spring lengths (m) at the pose",
    "family": "relaxed (L0 = d: both springs at their free length, V = 0) or parallel (the pose "
    "is on the curve where the springs' generalised forces are parallel; one free length chosen)",
    "physical": "both free lengths >= 0",
    "stable": "physical and the energy Hessian positive definite (eigenvalue > 1e-9 of the "
    "largest)",
    "hess_eig_min, hess_eig_max": "the Hessian's eigenvalues (J/rad^2) at the design",
    "grad_residual": "the norm of grad V (J/rad) at the design, by the energy code: 0 up to "
    "rounding",
}

BARRIERS = {
    "saddle_id": "the solution_id (solutions.csv) of a physical saddle of V",
    "min_a, min_b": "the solution_id of the minimum reached by gradient flow from the saddle "
    "along +v and -v (v: the eigenvector of the negative Hessian eigenvalue); empty if the flow "
    "did not end at a listed minimum",
    "barrier_a, barrier_b": "V(saddle) - V(end of that descent) (J): the energy to climb from "
    "that minimum over this saddle",
    "saddle_gamma1_deg, saddle_gamma2_deg": "the saddle's angles (deg)",
    "saddle_energy": "V at the saddle (J)",
    "saddle_eigenvalues": "the Hessian's eigenvalues at the saddle (J/rad^2), ascending",
    "converged": "both descents reached a point where Newton's step is below 1e-13 rad",
    "crosses_zero_length": "a descent passed a spring shorter than 1e-3 L3 (V is not smooth "
    "where a spring with L0 > 0 has zero length)",
    "min_spring_length": "the shortest spring length along both descents (m)",
    "lowest": "this saddle is the lowest joining its two distinct minima: their barrier",
}


FRAMEWORK_BARRIERS = {
    "saddle_id": "the solution_id (solutions.csv) of a physical critical point of index 1: a "
    "saddle, or with one degree of freedom a maximum",
    "min_a, min_b": "the solution_id of the minimum reached by gradient flow of V on the "
    "constraint set from the saddle along +v and -v (v: the eigenvector of the reduced "
    "Hessian's negative eigenvalue); empty if the flow did not converge or did not end at a "
    "listed minimum (within 1e-7 in the sweeps' match coordinates)",
    "barrier_a, barrier_b": "V(saddle) - V(end of that descent), in the file's units of k "
    "times length^2: the energy to climb from that minimum over this saddle",
    "BODY.angle_deg (BODY.qw ... BODY.qz), NODE.x ...": "the saddle's pose, named as in "
    "solutions.csv",
    "saddle_energy": "V at the saddle, as `energy` in solutions.csv",
    "saddle_eigenvalues": "eigenvalues of the Lagrangian's Hessian on the constraints' tangent "
    "space at the saddle, ascending, in the framework's normalised units (as hess_min_eig)",
    "converged": "both descents reached a point where Newton's step on the constraint set is "
    "below 1e-12 (normalised units) within max_steps steps",
    "crosses_zero_length": "a descent passed a spring or cable shorter than 1e-3 of the "
    "framework's length unit (its largest length): V has a cone point there if its L0 > 0",
    "min_spring_length": "the shortest spring or cable along both descents (the file's length "
    "unit)",
    "lowest": "this saddle is the lowest joining its two distinct minima: their barrier",
}

COUNTS = {
    "paths_tracked": "paths the solver tracked (homotopy: the generic set's nonsingular "
    "solutions; cli: the total degree)",
    "finite_endpoints": "tracked paths that ended at a finite point",
    "closed_form_endpoints": "endpoints computed in closed form instead of tracked: the double "
    "roots where one spring with L0 > 0 has zero length (d = 0), one endpoint each",
    "infinite_or_failed_paths": "tracked paths that went to infinity or failed",
    "lost_paths": "failed paths that may have hidden a solution (the status is then incomplete)",
    "crossings_unresolved": "paths that crossed another path where the solver could not part "
    "them (Bertini's own warning: the affected solutions may be wrong); each is also a lost "
    "path or in an incomplete generic set, and the status is then incomplete",
    "distinct_solutions": "rows of solutions.csv: every distinct finite solution, real or not "
    "(= real + complex)",
    "real": "real rows, physical or not (= physical + negative_d + zero_length_real)",
    "complex": "non-real rows (zero_length_complex of them have a spring of zero length)",
    "physical": "physical rows: the equilibria of the mechanism",
    "stable": "stable rows: strict local minima of V (a subset of physical)",
    "negative_d": "real rows with a spring length d < 0 (reason negative_d; always real)",
    "zero_length_real": "real rows where a spring with L0 > 0 has zero length (reason "
    "zero_length_spring and real): the cone points of V, not equilibria",
    "zero_length_complex": "non-real rows where a spring with L0 > 0 has zero length (reason "
    "zero_length_spring, not real; also the points where both springs do)",
    "singular": "rows flagged singular, whatever their reason (the closed-form d = 0 roots among "
    "them)",
}


FRAMEWORK = {
    "solution_id": "1, 2, ...: physical rows first, then other real roots, then complex ones; "
    "within each group by energy",
    "BODY.x, BODY.y (BODY.z)": "world position of the origin of the body's own frame",
    "BODY.angle_deg": "planar: the body's rotation (deg) in [0, 360)",
    "BODY.qw, BODY.qx, BODY.qy, BODY.qz": "spatial: the body's rotation as a unit quaternion "
    "(q and -q are one pose and one row: the sign shown makes the first component larger than "
    "1e-9 in magnitude positive, so a half turn's qw of 1e-17 does not choose it)",
    "BODY.POINT.x, .y (.z)": "world coordinates of each named point of each body",
    "NODE.x, .y (.z)": "world coordinates of each node",
    "NAME.length": "spring or cable: its length (the signed length unknown where it has a free "
    "length, so negative on rows that are not physical); bar: its length",
    "NAME.tension": "spring: k (d - L0), > 0 in tension; cable: the same when taut, 0 when "
    "slack; bar: its force, > 0 in tension",
    "NAME.taut": "cable: taut in the system this row solves (see taut_set)",
    "energy": "V = sum k/2 (d - L0)^2 over springs + sum k/2 max(d - L0, 0)^2 over cables - "
    "sum F . x over loads (real parts for complex rows)",
    "is_real": "every unknown has |Im| < 1e-8 relative to 1 + |Re| (in the framework's units)",
    "singular": "jacobian_condition > 1e12, or several path endpoints at this solution",
    "physical": "real, every spring and cable with a free length has d > 0, and the taut set is "
    "consistent (taut cables longer than L0, slack ones not)",
    "stable": "physical and kind min",
    "kind": "physical rows: min, saddle, max of V on the constraint set (Hessian of the "
    "Lagrangian reduced to the constraints' tangent space), or degenerate (an eigenvalue within "
    "1e-9 of 0 relative to the largest Hessian entry, a singular root, or a cable at its free "
    "length)",
    "index": "physical rows: the number of negative reduced-Hessian eigenvalues (-1 otherwise)",
    "reason": "why a row is not physical: complex, negative_length:NAME, cable_pushes:NAME (a "
    "taut cable shorter than L0), slack_cable_stretched:NAME (a slack one longer), "
    "switch_duplicate:NAME (an equilibrium with cable NAME at its free length, found by both "
    "taut sets: this is the second row of it), continuum:N (a point of continuum N of "
    "continua.csv, counted there, not as an isolated equilibrium); empty if physical",
    "hess_min_eig": "the smallest reduced-Hessian eigenvalue (the framework's units)",
    "max_imag": "the largest |Im| / (1 + |Re|) over the unknowns",
    "residual": "max |f_i| of the polynomial system at the refined point (framework's units)",
    "jacobian_condition": "condition number of the system's Jacobian at the refined point",
    "multiplicity": "how many path endpoints reached this solution (a spatial body's q and -q "
    "are reached by paths of their own: counted once)",
    "taut_set": "the cables taut in the polynomial system that gave this row",
    "paths": "the path numbers that reached it (for a spatial body, those to q and to -q; on "
    "the real route the search's number of the root, from 0)",
}

FRAMEWORK_COUNTS = {
    "paths_tracked": "paths tracked over every taut set (the generic sets' finite nonsingular "
    "roots)",
    "generic_paths": "paths of the ab-initio generic solves (multihomogeneous start), one seed",
    "finite_endpoints": "tracked paths that ended at a finite point",
    "infinite_or_failed_paths": "tracked paths that went to infinity or failed",
    "lost_paths": "failed paths that may have hidden a solution (the status is then incomplete)",
    "crossings_unresolved": "paths, over every taut set, that crossed another path where the "
    "solver could not part them (tracking to the point, and the generic sets it started from)",
    "distinct_solutions": "rows of solutions.csv",
    "real, physical, stable, singular": "rows that are so",
    "taut_sets_solved": "taut sets solved (cables always taut or never taut are not enumerated)",
    "taut_sets_continuum": "taut sets where something moves freely (see details.taut_sets)",
    "taut_sets_pruned": "taut sets no pose can hold, not solved (bound smoothing; the proof "
    "in details.taut_sets)",
    "closed_form_endpoints": "0: a framework has no closed-form roots",
    "continua": "continua of equilibria (continua.csv; run.json `continua`), not in the counts "
    "above",
}

FRAMEWORK_CONTINUA = {
    "continuum": "its number N (rows on it in solutions.csv have reason continuum:N)",
    "taut_set": "the cables taut along it",
    "dimension": "1: a curve, traced; 2 or more: found (the Jacobian's null space), not traced",
    "shape": "arc (two ends), closed curve, or not traced",
    "kind": "neutral minima (V constant along it, rising across: index 0 across), neutral "
    "saddles (index k across), or degenerate across the curve somewhere",
    "index_across": "the number of negative reduced-Hessian eigenvalues across the curve",
    "energy, energy_spread": "V's mean and range over its traced points (user units)",
    "BODY.angle_deg.min, .max": "the body angle's range along it (interior extremes refined on "
    "the curve; 0 and 360 where it winds around)",
    "end1_by, end2_by": "what ends an arc: a slack cable reaching its free length (turns taut), "
    "a taut one reaching it (turns slack), a spring's zero length, or a singular point",
    "end1.BODY.angle_deg, end2...": "the pose of each end",
    "points": "points traced along it",
    "morse_term, morse_note": "its term in the Morse sum (an arc of minima ended by cables "
    "turning taut: 1; a closed curve: 0; docs/frameworks.md), or empty and why none is known",
}


FRAMEWORK_SWEEP = {
    "point": "index of the sweep point (grid order; the second parameter varies fastest)",
    "<param>, <param2>": "the swept framework parameters' values at this point",
    "framework solutions.csv columns": "as in a framework's solutions.csv, one row per finite "
    "solution of the point (every taut set)",
    "method": "how each taut set was solved: Newton from the neighbouring point (complete: as "
    "many distinct nonsingular roots as the generic set), or parameter homotopy from the generic "
    "set (with why Newton was refused)",
    "lost_paths": "paths that failed at this point, over every taut set",
    "status": "ok, or incomplete when a completeness check of the point failed",
    "branch": "1-D sweeps: which branch the row belongs to (secant prediction + one-to-one "
    "assignment on the poses and link lengths; complex rows by their real parts)",
}

FRAMEWORK_EVENTS = {
    "kind": "what happens there: cable_switch (equilibria appear or vanish where a cable of theirs "
    "reaches its free length: the taut and the slack branch end together, the Hessian regular, "
    "so no fold; a pair born or vanishing there is a border collision, one row each, and two "
    "pairs at one switch are two rows), fold (the number of physical equilibria changes by two: "
    "a pair is born or "
    "meets and vanishes, the reduced Hessian singular there), pitchfork (it changes by two on a "
    "third equilibrium, present on both sides, through the pair's meeting point: a min and two "
    "saddles, or a saddle and two minima, meet), physical_change "
    "(it changes by one: a length reaches 0; where an equilibrium comes out of or goes into a "
    "cone point of V, a spring with a free length at zero length, the description says so) or "
    "stability_change (the number of stable ones "
    "changes; at the events above too)",
    "branches": "the branch ids of the rows involved (a+b; a+b+c at a pitchfork, the third "
    "branch among them) at the neighbouring sweep point where they exist: its physical rows "
    "nearest in pose to the event",
    "<param>": "the event's parameter value: of a fold on the real route, the solution of the "
    "fold system (grad V = 0, H v = 0) Newton converged to from the pair that meets there (its "
    "bracket then proved by one complete solve on each side); else the middle of the final "
    "bisection bracket; of a "
    "fold the probes could not close in on (the solver sees the merging pair as one degenerate "
    "root or leaves it undecided), the zero of the parabola through three probes of the merging "
    "pair's eigenvalue product; of a cable switch, where the followed equilibrium's cable "
    "length equals its free length; of an equilibrium leaving a cone point, where the other "
    "elements' pull there equals the spring's k L0",
    "pose columns": "BODY.angle_deg (planar), BODY.qw ... (spatial), NODE.x ...: the mean pose "
    "of the equilibria that appear or vanish, at the bracket's end where they are real (those "
    "with no counterpart at the other end); of a stability change alone, of the row whose "
    "smallest eigenvalue is nearest 0; of a cable switch, the followed equilibrium where its "
    "cable is at its free length",
    "hess_min_eig": "the largest |smallest reduced-Hessian eigenvalue| of those equilibria there "
    "(tends to 0 at a fold of a minimum and a saddle and at a pitchfork; at a fold of two "
    "saddles the eigenvalue that crosses 0 is another one; away from 0 at a cable switch)",
    "refined": "every probe that placed an end of the bracket was a complete solve (status ok); "
    "a probe that sees the event itself (counts matching neither end, with a degenerate row or "
    "a failed check: at a fold, the merging pair taken as one root) places no end; a cable "
    "switch: also its secant converged",
    "bracket": "the value's accuracy: the width between the complete solves on either side of "
    "it (a located fold: 1e-9 relative, wider only where a solve that near sees the pair as one "
    "root); the final bisection bracket's width (1e-9 relative, or as "
    "narrow as the probes that see the event allow); of an extrapolated fold, the parabola's "
    "zero's distance from the line's through the two nearest probes; of a cable switch or a "
    "cone point, the secant's next step on d - L0 of its cable or on pull - k L0 (converged to "
    "1e-9 relative; 0 where it landed exactly, as on a branch that does not depend on the "
    "parameter)",
    "description": "what happens, in words (a cable switch names its cable, a cone point its "
    "spring); where sweep points between the two that bracket the event were left out (a point "
    "whose solve is incomplete or has a degenerate equilibrium, e.g. one sitting on a cable's "
    "switch, places no bracket end: its counts may be wrong), it ends with '; sweep point "
    "P = v left out (incomplete or degenerate solve)'",
    "lo, hi": "the sweep points on either side (where the counts change twice between them, "
    "each event is found and carries both)",
}


_MOVE_HEAD = {
    "step": "0, 1, ...: the row's order along the move",
    "s": "path position: 0 at the first waypoint, k at waypoint k, linear in between",
    "NAME (each path parameter)": "its value at this row",
    "event": "step (one of `steps` equal steps a segment), snap_from (the followed state where "
    "it ends: a fold or a cable switch, located to 1e-10 in s) or snap_to (the minimum it fell "
    "into, just past that point)",
}

MOVE = {
    **_MOVE_HEAD,
    "gamma1_deg, gamma2_deg": "the state's angles (deg) in [0, 360)",
    "d1, d2": "spring lengths (m)",
    "energy": "V (J)",
    "hess_min_eig": "the Hessian's smallest eigenvalue over max(k1, k2) L3^2: > 0 at every "
    "step row (the state is a minimum), near 0 at a fold",
}

FRAMEWORK_MOVE = {
    **_MOVE_HEAD,
    "BODY.angle_deg (BODY.qw ... BODY.qz), BODY.POINT.x ..., NODE.x ...": "the state's pose, "
    "named as in solutions.csv",
    "NAME.length": "every link's length",
    "NAME.tension": "spring: k (d - L0); cable: the same when taut, 0 when slack",
    "NAME.taut": "cable: longer than its free length",
    "energy": "V, as in solutions.csv",
    "hess_min_eig": "the reduced Hessian's smallest eigenvalue (normalised units, as in "
    "solutions.csv): > 0 at every step row, near 0 at a fold",
}

PLAN = {
    "NAME (each of the map's two parameters)": "one row a waypoint of the actuator path, in "
    "order: the first and the last are the solve's values (the actuators return), the others "
    "grid points of the map where the path turns; cb.move along them (trajectory.csv, "
    "snaps.csv here) ends in the goal state",
}

SNAPS = {
    "snap": "1, 2, ... along the move",
    "s": "path position where the followed state ends (its last located point)",
    "NAME (each path parameter)": "its value there",
    "kind": "fold (the softest Hessian eigenvalue fell below 1e-3, normalised), cable_switch (a "
    "cable within 1e-6 length units of its free length: V is piecewise there), unexplained "
    "(neither), or degenerate (the descent ended within 1e-4 of where it began: a cusp or a "
    "pitchfork on the path, the branch taken not the model's to say); the last two are warnings",
    "released": "V(state before) - V(minimum after), both at the parameter values just past the "
    "end (J, or the file's units of k length^2)",
    "located_to": "the width of the final bracket of the end, in the path's parameters (the "
    "largest change of one parameter)",
    "softest_eig": "the softest normalised Hessian eigenvalue of the state where it ends",
    "cable_gap": "the smallest |d - L0| over cables there (length units; inf: no cable)",
    "landed": "the gradient flow from just past the end reached a minimum (else the move "
    "stops there, status incomplete)",
    "before.COLUMN, after.COLUMN": "the pose columns and energy of the state where it ends "
    "and of the minimum it falls into",
}


def markdown(title: str, columns: dict[str, str], head: str = "column") -> str:
    """A Markdown table of columns (or other names) and their meanings."""
    lines = [f"## {title}", "", f"| {head} | meaning |", "|---|---|"]
    lines += [f"| `{name}` | {text} |" for name, text in columns.items()]
    return "\n".join(lines) + "\n"


def reference(*tables: str, title: str = "Columns of the CSV files in this folder") -> str:
    """The column reference of a run folder: 'solutions', 'counts', 'sweep', 'events',
    'barriers', 'folds', 'regions', 'design', 'framework', 'framework_counts',
    'framework_continua', 'framework_sweep', 'framework_events', 'framework_folds',
    'framework_regions', 'framework_barriers', 'move', 'framework_move', 'snaps', 'plan'."""
    known = {
        "solutions": ("solutions.csv", SOLUTIONS),
        "counts": ("counts (run.json `counts`, `res.counts`)", COUNTS, "count"),
        "sweep": ("sweep.csv", SWEEP),
        "events": ("events.csv", EVENTS),
        "barriers": ("barriers.csv", BARRIERS),
        "framework_barriers": ("barriers.csv of a framework", FRAMEWORK_BARRIERS),
        "move": ("trajectory.csv (`cb.move`)", MOVE),
        "framework_move": ("trajectory.csv of a framework's move", FRAMEWORK_MOVE),
        "snaps": ("snaps.csv", SNAPS),
        "plan": ("plan.csv (`cb.plan`)", PLAN),
        "folds": ("folds.csv (`cb.fold_curves`)", FOLDS),
        "regions": ("regions.csv", REGIONS),
        "design": ("the design CSV (`cotm-bertini design --out`)", DESIGN),
        "framework": ("solutions.csv of a framework (`--framework`)", FRAMEWORK),
        "framework_counts": ("counts of a framework solve", FRAMEWORK_COUNTS, "count"),
        "framework_continua": ("continua.csv of a framework", FRAMEWORK_CONTINUA),
        "framework_sweep": ("sweep.csv of a framework", FRAMEWORK_SWEEP),
        "framework_events": ("events.csv of a framework", FRAMEWORK_EVENTS),
        "framework_folds": ("folds.csv of a framework's map", FRAMEWORK_FOLDS),
        "framework_regions": ("regions.csv of a framework's map", FRAMEWORK_REGIONS),
    }
    parts = [f"# {title}\n"]
    parts += [markdown(*known[t]) for t in tables]
    return "\n".join(parts)


def document() -> str:
    """docs/columns.md: every table's columns."""
    return reference(
        "solutions",
        "counts",
        "sweep",
        "events",
        "barriers",
        "folds",
        "regions",
        "design",
        "framework",
        "framework_counts",
        "framework_continua",
        "framework_sweep",
        "framework_events",
        "framework_folds",
        "framework_regions",
        "framework_barriers",
        "move",
        "framework_move",
        "snaps",
        "plan",
        title="Columns of the CSV files",
    )
