"""Navigation: the occupancy map, OMPL routes, the route follower and the navigator that runs them."""
