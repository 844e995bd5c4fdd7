"""What every cloud renderer shares: the simulation's texture sets and layout, the light model and its
binding, the off-screen clouds and the edge fade."""
