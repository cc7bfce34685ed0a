# office.sc -- a small office for the lighting-design walkthrough.
#
# A closed room 5 m wide (x), 4 m deep (z) and 2.8 m high (y up) with the
# design reflectances of EN 12464-1 (ceiling 0.8, walls 0.6, floor 0.3), a
# desk, a stool and a low cabinet, and four 600 x 600 mm ceiling panels
# (material `luminaire`, 5 mm below the ceiling, facing down).
#
# Units: metres: run it with --units m.  On its own the panels are
# Lambertian with an exitance of 10,000 lm/m² (3,600 lm each); with
#   --ies luminaire=scenes/luminaires/panel.ies
# each panel emits the distribution of that file instead (written for this
# project; see its header).
#
# Orientation: the room's polygons face into the room, the panels face
# down with their first edge along +x (their C0 plane), boxes face out.

camera
  eye 0.35 1.6 0.3
  lookat 3.0 0.6 2.6
  up 0 1 0
  fov 70
  size 640 480
end

material ceiling
  color 1 1 1
  k_diffrefl 0.8           # rho = 0.8
end
material wall
  color 0.98 0.95 0.9
  k_diffrefl 0.62          # rho = 0.61 0.59 0.56, off-white
end
material floor
  color 0.9 0.75 0.6
  k_diffrefl 0.4           # rho = 0.36 0.3 0.24, light oak
end
material desk
  color 0.85 0.8 0.7
  k_diffrefl 0.6           # rho = 0.51 0.48 0.42, maple laminate
end
material steel
  color 0.5 0.5 0.52
  k_diffrefl 1             # rho = 0.5 0.5 0.52
end
material fabric
  color 0.2 0.3 0.5
  k_diffrefl 1             # rho = 0.2 0.3 0.5, blue upholstery
end
material luminaire
  color 1 1 1
  k_emission 10000         # lm/m² (replaced by --ies)
end

# ---- the room ----
# floor (y = 0), facing up
polygon floor
  vertex 0 0 0
  vertex 0 0 4
  vertex 5 0 4
  vertex 5 0 0
end
# ceiling (y = 2.8), facing down
polygon ceiling
  vertex 0 2.8 0
  vertex 5 2.8 0
  vertex 5 2.8 4
  vertex 0 2.8 4
end
# x = 0 wall, facing +x
polygon wall
  vertex 0 0 0
  vertex 0 2.8 0
  vertex 0 2.8 4
  vertex 0 0 4
end
# x = 5 wall, facing -x
polygon wall
  vertex 5 0 0
  vertex 5 0 4
  vertex 5 2.8 4
  vertex 5 2.8 0
end
# back wall (z = 4), facing -z
polygon wall
  vertex 0 0 4
  vertex 0 2.8 4
  vertex 5 2.8 4
  vertex 5 0 4
end
# front wall (z = 0), facing +z
polygon wall
  vertex 0 0 0
  vertex 5 0 0
  vertex 5 2.8 0
  vertex 0 2.8 0
end

# ---- four ceiling panels, 0.6 x 0.6, facing down, on a 2.5 x 2 m grid ----
polygon luminaire
  vertex 0.95 2.795 0.7
  vertex 1.55 2.795 0.7
  vertex 1.55 2.795 1.3
  vertex 0.95 2.795 1.3
end
polygon luminaire
  vertex 0.95 2.795 2.7
  vertex 1.55 2.795 2.7
  vertex 1.55 2.795 3.3
  vertex 0.95 2.795 3.3
end
polygon luminaire
  vertex 3.45 2.795 0.7
  vertex 4.05 2.795 0.7
  vertex 4.05 2.795 1.3
  vertex 3.45 2.795 1.3
end
polygon luminaire
  vertex 3.45 2.795 2.7
  vertex 4.05 2.795 2.7
  vertex 4.05 2.795 3.3
  vertex 3.45 2.795 3.3
end

# ---- the desk: top 1.6 x 0.8, 25 mm thick, at 0.72..0.745 m ----
box desk 1.7 0.72 1.6  3.3 0.745 2.4
box steel 1.75 0 1.65  1.8 0.72 1.7
box steel 3.2 0 1.65  3.25 0.72 1.7
box steel 1.75 0 2.3  1.8 0.72 2.35
box steel 3.2 0 2.3  3.25 0.72 2.35

# ---- a stool: seat and post (below the work plane, whose points
# inside furniture would read 0 lx) ----
box fabric 2.25 0.42 2.45  2.75 0.48 2.95
box steel 2.48 0 2.68  2.52 0.42 2.72

# ---- a low cabinet (0.7 m) against the back wall ----
box steel 0.3 0 3.5  1.5 0.7 3.98
