"""The real route's machinery: branch and bound over boxes of a framework's configuration space
in interval arithmetic (boxes), shared over processes (box_shares), with the landscapes it
searches (real_route: circles and tori, a four-bar's loop, free nodes; spheres: nodes on bars;
rotations: bodies on ball joints), the tests it applies (krawczyk, cones, stability, minima) and
each link's enclosures (links, loops, free_nodes). Bertini's engines live in backends."""
