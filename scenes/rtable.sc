# rtable.sc -- a room with a table lit by one ceiling lamp.
#
# In the spirit of the classic radiosity test picture: a closed room with
# walls of different colours (red on the left of the picture, blue-green
# on the right, a pale cream back wall, white ceiling, light grey floor)
# so that colour bleeding shows on the table, the floor and the ceiling;
# a square warm-white lamp just below the ceiling;
# a table (top and four legs) with a small yellow box on it.
#
# Units: metres (any unit works; used consistently).  The room spans
# x 0..5 (width), y 0..3 (height, y up), z 0..5 (depth).  The camera stands
# near the front wall (z = 0) and looks at the table.
#
# Orientation: the room's polygons face into the room, the lamp faces down,
# boxes face outward (as the format defines them).

camera
  eye 2.5 1.7 0.35
  lookat 2.5 0.75 3.0
  up 0 1 0
  fov 55
  size 640 480
end

material white
  color 0.8 0.8 0.8
  k_diffrefl 0.95          # rho = 0.76
end
material floor_grey
  color 0.7 0.68 0.64
  k_diffrefl 1             # rho = 0.7 0.68 0.64, a warm light grey
end
material red_wall
  color 0.8 0.12 0.1
  k_diffrefl 1             # rho = 0.8 0.12 0.1
end
material bluegreen_wall
  color 0.1 0.5 0.6
  k_diffrefl 1             # rho = 0.1 0.5 0.6
end
material back_wall
  color 0.75 0.72 0.55
  k_diffrefl 1             # rho = 0.75 0.72 0.55, pale cream
end
material wood
  color 0.6 0.4 0.22
  k_diffrefl 1             # rho = 0.6 0.4 0.22
end
material yellow
  color 0.8 0.7 0.1
  k_diffrefl 1             # rho = 0.8 0.7 0.1
end
material lamp
  color 1 0.9 0.75         # warm white
  k_emission 15            # e = 15 13.5 11.25
end

# ---- the room: every polygon's front faces into the room ----

# floor (y = 0), facing up
polygon floor_grey
  vertex 0 0 0
  vertex 0 0 5
  vertex 5 0 5
  vertex 5 0 0
end
# ceiling (y = 3), facing down
polygon white
  vertex 0 3 0
  vertex 5 3 0
  vertex 5 3 5
  vertex 0 3 5
end
# x = 0 wall, blue-green, facing +x (on the picture's right: the camera
# looks along +z, so +x is to its left)
polygon bluegreen_wall
  vertex 0 0 0
  vertex 0 3 0
  vertex 0 3 5
  vertex 0 0 5
end
# x = 5 wall, red, facing -x (on the picture's left)
polygon red_wall
  vertex 5 0 0
  vertex 5 0 5
  vertex 5 3 5
  vertex 5 3 0
end
# back wall (z = 5), facing -z
polygon back_wall
  vertex 0 0 5
  vertex 0 3 5
  vertex 5 3 5
  vertex 5 0 5
end
# front wall (z = 0, behind the camera), facing +z
polygon white
  vertex 0 0 0
  vertex 5 0 0
  vertex 5 3 0
  vertex 0 3 0
end

# ---- the lamp: a 1 x 1 square 0.02 below the ceiling, facing down ----
polygon lamp
  vertex 2 2.98 2.3
  vertex 3 2.98 2.3
  vertex 3 2.98 3.3
  vertex 2 2.98 3.3
end

# ---- the table: top 1.6 x 1.2, 0.06 thick, at height 0.72..0.78 ----
# table top
box wood 1.7 0.72 2.2  3.3 0.78 3.4
# table legs, 0.07 x 0.07, standing on the floor, touching the top
box wood 1.75 0 2.25  1.82 0.72 2.32
box wood 3.18 0 2.25  3.25 0.72 2.32
box wood 1.75 0 3.28  1.82 0.72 3.35
box wood 3.18 0 3.28  3.25 0.72 3.35

# ---- a small box standing on the table ----
box yellow 2.55 0.78 2.65  2.85 1.08 2.95
