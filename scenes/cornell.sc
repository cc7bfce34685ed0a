# cornell.sc -- the Cornell box (the version with two white blocks).
#
# Source: "Cornell Box Data", Cornell University Program of Computer
# Graphics (graphics.cornell.edu/online/box/data.html): the measured
# geometry of the floor, light, ceiling, back wall, right (green) wall,
# left (red) wall, short block and tall block, and the camera.
# Units: millimetres, as in the published data.
#
# Changes from the published data, each noted at its polygon:
#  - the left (red) wall is not planar in the data (one corner is ~3 mm off
#    the plane of the other three); one vertex is moved onto that plane;
#  - the light is lowered 0.5 mm below the ceiling (y = 548.3) so that it is
#    not coplanar with the ceiling, which is kept whole (no hole);
#  - the published reflectances are spectral; RGB approximations are used.
#
# Orientation: x runs from the green wall (x = 0) to the red wall
# (x ~ 556), y is up, z runs from the open front (z = 0) to the back wall
# (z = 559.2).  The camera looks along +z with up +y, so its right is -x:
# the red wall is on the left of the picture and the green one on the
# right.  Walls, floor and ceiling face into the box, the light faces
# down, the blocks' faces face outward.  The front (z = 0) is open.

# Published: position 278 273 -800, direction 0 0 1, up 0 1 0, focal
# length 0.035, film 0.025 x 0.025, so the vertical field of view is
# 2 * atan(0.0125 / 0.035) = 39.31 degrees.
camera
  eye 278 273 -800
  lookat 278 273 0
  up 0 1 0
  fov 39.31
  size 512 512
end

# RGB approximations of the measured spectral reflectances.
material white
  color 0.73 0.73 0.73
  k_diffrefl 1             # rho = 0.73 0.73 0.73
end
material red
  color 0.63 0.065 0.05
  k_diffrefl 1             # rho = 0.63 0.065 0.05
end
material green
  color 0.14 0.45 0.091
  k_diffrefl 1             # rho = 0.14 0.45 0.091
end
# Warm-white light: e = k_emission * color = 17 11.9 4.25.
material light
  color 1 0.7 0.25
  k_emission 17
end

# floor, facing up
polygon white
  vertex 552.8 0.0   0.0
  vertex   0.0 0.0   0.0
  vertex   0.0 0.0 559.2
  vertex 549.6 0.0 559.2
end

# light, facing down.  Published at y = 548.8 (in the ceiling's plane);
# here at y = 548.3, 0.5 below the ceiling, so the two are not coplanar.
polygon light
  vertex 343.0 548.3 227.0
  vertex 343.0 548.3 332.0
  vertex 213.0 548.3 332.0
  vertex 213.0 548.3 227.0
end

# ceiling, facing down (kept whole: the light hangs just below it)
polygon white
  vertex 556.0 548.8   0.0
  vertex 556.0 548.8 559.2
  vertex   0.0 548.8 559.2
  vertex   0.0 548.8   0.0
end

# back wall, facing the camera (-z)
polygon white
  vertex 549.6   0.0 559.2
  vertex   0.0   0.0 559.2
  vertex   0.0 548.8 559.2
  vertex 556.0 548.8 559.2
end

# right wall (green, x = 0), facing +x
polygon green
  vertex 0.0   0.0 559.2
  vertex 0.0   0.0   0.0
  vertex 0.0 548.8   0.0
  vertex 0.0 548.8 559.2
end

# left wall (red), facing -x.  ADJUSTED: the published corners
#   552.8 0 0 / 549.6 0 559.2 / 556.0 548.8 559.2 / 556.0 548.8 0
# are not coplanar (the last-but-one is 3.2 off the plane of the other three
# along x, far beyond the format's tolerance).  The back top corner is moved
# from x = 556.0 to x = 552.8, onto the plane of the other three.  The
# ceiling and back wall then reach 3.2 past this wall at that corner, hidden
# behind it; there is no gap.
polygon red
  vertex 552.8   0.0   0.0
  vertex 549.6   0.0 559.2
  vertex 552.8 548.8 559.2
  vertex 556.0 548.8   0.0
end

# short block: top
polygon white
  vertex 130.0 165.0  65.0
  vertex  82.0 165.0 225.0
  vertex 240.0 165.0 272.0
  vertex 290.0 165.0 114.0
end
# short block: side
polygon white
  vertex 290.0   0.0 114.0
  vertex 290.0 165.0 114.0
  vertex 240.0 165.0 272.0
  vertex 240.0   0.0 272.0
end
# short block: side
polygon white
  vertex 130.0   0.0  65.0
  vertex 130.0 165.0  65.0
  vertex 290.0 165.0 114.0
  vertex 290.0   0.0 114.0
end
# short block: side
polygon white
  vertex  82.0   0.0 225.0
  vertex  82.0 165.0 225.0
  vertex 130.0 165.0  65.0
  vertex 130.0   0.0  65.0
end
# short block: side
polygon white
  vertex 240.0   0.0 272.0
  vertex 240.0 165.0 272.0
  vertex  82.0 165.0 225.0
  vertex  82.0   0.0 225.0
end

# tall block: top
polygon white
  vertex 423.0 330.0 247.0
  vertex 265.0 330.0 296.0
  vertex 314.0 330.0 456.0
  vertex 472.0 330.0 406.0
end
# tall block: side
polygon white
  vertex 423.0   0.0 247.0
  vertex 423.0 330.0 247.0
  vertex 472.0 330.0 406.0
  vertex 472.0   0.0 406.0
end
# tall block: side
polygon white
  vertex 472.0   0.0 406.0
  vertex 472.0 330.0 406.0
  vertex 314.0 330.0 456.0
  vertex 314.0   0.0 456.0
end
# tall block: side
polygon white
  vertex 314.0   0.0 456.0
  vertex 314.0 330.0 456.0
  vertex 265.0 330.0 296.0
  vertex 265.0   0.0 296.0
end
# tall block: side
polygon white
  vertex 265.0   0.0 296.0
  vertex 265.0 330.0 296.0
  vertex 423.0 330.0 247.0
  vertex 423.0   0.0 247.0
end
