# table_chair.sc -- a dining corner lit by three light sources.
#
# A closed room with coloured walls, a table with a small vase-like box on
# it, two chairs turned at angles to the table (placed with transform
# blocks, one of them nested), and a low cabinet against the back wall.
# Light comes from a warm-white ceiling panel over the table, a cool-white
# ceiling panel over the cabinet, and a window-like bluish daylight panel
# on the terracotta wall.
#
# Units: metres.  The room spans x 0..6 (width), y 0..3 (height, y up),
# z 0..5 (depth).  The camera stands in the front corner at x = 0, z = 0
# and looks diagonally across the room: the terracotta wall with the window
# (x = 6) is ahead on the left of the picture, the pale blue back wall
# (z = 5) with the cabinet on the right; the sage green wall (x = 0) is
# mostly behind the camera but reflects light onto the rest.
#
# Orientation: the room's walls face into the room, the ceiling panels face
# down, the window panel faces into the room; boxes face outward.

camera
  eye 0.35 1.9 0.3
  lookat 3.4 1.0 3.8
  up 0 1 0
  fov 65
  size 640 480
end

# ---- materials: rho = k_diffrefl * color, every channel < 1 ----
material ceiling_white
  color 0.8 0.8 0.78
  k_diffrefl 1             # rho = 0.8 0.8 0.78
end
material floor_oak
  color 0.62 0.5 0.35
  k_diffrefl 1             # rho = 0.62 0.5 0.35
end
material terracotta
  color 0.75 0.35 0.2
  k_diffrefl 1             # rho = 0.75 0.35 0.2
end
material sage
  color 0.45 0.62 0.4
  k_diffrefl 1             # rho = 0.45 0.62 0.4
end
material pale_blue
  color 0.55 0.65 0.78
  k_diffrefl 1             # rho = 0.55 0.65 0.78
end
material walnut
  color 0.45 0.28 0.15
  k_diffrefl 1             # rho = 0.45 0.28 0.15
end
material chair_blue
  color 0.15 0.3 0.65
  k_diffrefl 1             # rho = 0.15 0.3 0.65
end
material cabinet_grey
  color 0.6 0.6 0.58
  k_diffrefl 1             # rho = 0.6 0.6 0.58
end
material vase_yellow
  color 0.85 0.7 0.15
  k_diffrefl 1             # rho = 0.85 0.7 0.15
end
# warm-white panel (about 3000 K): e = 12 9.84 7.2
material lamp_warm
  color 1 0.82 0.6
  k_emission 12
end
# cool-white panel (about 6500 K): e = 8 9 10
material lamp_cool
  color 0.8 0.9 1
  k_emission 10
end
# daylight through a window: e = 5.1 5.52 6
material daylight
  color 0.85 0.92 1
  k_emission 6
end

# ---- the room: every polygon's front faces into the room ----

# floor (y = 0), facing up
polygon floor_oak
  vertex 0 0 0
  vertex 0 0 5
  vertex 6 0 5
  vertex 6 0 0
end
# ceiling (y = 3), facing down
polygon ceiling_white
  vertex 0 3 0
  vertex 6 3 0
  vertex 6 3 5
  vertex 0 3 5
end
# x = 0 wall, sage green, facing +x
polygon sage
  vertex 0 0 0
  vertex 0 3 0
  vertex 0 3 5
  vertex 0 0 5
end
# x = 6 wall, terracotta, facing -x
polygon terracotta
  vertex 6 0 0
  vertex 6 0 5
  vertex 6 3 5
  vertex 6 3 0
end
# back wall (z = 5), pale blue, facing -z
polygon pale_blue
  vertex 0 0 5
  vertex 0 3 5
  vertex 6 3 5
  vertex 6 0 5
end
# front wall (z = 0, behind the camera), facing +z
polygon ceiling_white
  vertex 0 0 0
  vertex 6 0 0
  vertex 6 3 0
  vertex 0 3 0
end

# ---- light sources ----

# warm ceiling panel over the table, 0.8 x 0.8, 0.02 below the ceiling,
# facing down
polygon lamp_warm
  vertex 3.3 2.98 2.1
  vertex 4.1 2.98 2.1
  vertex 4.1 2.98 2.9
  vertex 3.3 2.98 2.9
end
# cool ceiling panel over the cabinet, 0.6 x 0.6, facing down
polygon lamp_cool
  vertex 0.8 2.98 3.9
  vertex 1.4 2.98 3.9
  vertex 1.4 2.98 4.5
  vertex 0.8 2.98 4.5
end
# window: a 1.6 wide x 1.2 high daylight panel 0.01 in front of the
# terracotta wall, facing -x into the room
polygon daylight
  vertex 5.99 1.0 1.8
  vertex 5.99 1.0 3.4
  vertex 5.99 2.2 3.4
  vertex 5.99 2.2 1.8
end

# ---- the table: top 1.8 x 1.0 at height 0.72..0.77, legs 0.06 square ----
# table top
box walnut 2.8 0.72 2.0  4.6 0.77 3.0
# table legs
box walnut 2.86 0 2.06  2.92 0.72 2.12
box walnut 4.48 0 2.06  4.54 0.72 2.12
box walnut 2.86 0 2.88  2.92 0.72 2.94
box walnut 4.48 0 2.88  4.54 0.72 2.94
# a small vase-like box on the table
box vase_yellow 3.5 0.77 2.4  3.68 1.05 2.58

# ---- a low cabinet against the back wall, under the cool panel ----
box cabinet_grey 0.5 0 4.5  1.7 0.8 5.0

# ---- chair 1: modelled at the origin facing -z (backrest on the +z
# side), turned -110 degrees about y so it faces the table's x = 2.8 end
# at a slant, then moved beside that end ----
transform
  translate 2.3 0 2.45
  rotate 0 1 0 -110
  # seat, 0.44 x 0.44, 0.05 thick
  box chair_blue -0.22 0.43 -0.22  0.22 0.48 0.22
  # legs, 0.04 square
  box chair_blue -0.21 0 -0.21  -0.17 0.43 -0.17
  box chair_blue  0.17 0 -0.21   0.21 0.43 -0.17
  box chair_blue -0.21 0  0.17  -0.17 0.43  0.21
  box chair_blue  0.17 0  0.17   0.21 0.43  0.21
  # backrest
  box chair_blue -0.22 0.48 0.18  0.22 0.95 0.22
end

# ---- chair 2: the same chair, placed with nested transforms: the inner
# block turns it 115 degrees about y (facing -x, slanted), the outer block
# then moves it beside the table's x = 4.6 end ----
transform
  translate 5.1 0 2.6
  transform
    rotate 0 1 0 115
    # seat
    box chair_blue -0.22 0.43 -0.22  0.22 0.48 0.22
    # legs
    box chair_blue -0.21 0 -0.21  -0.17 0.43 -0.17
    box chair_blue  0.17 0 -0.21   0.21 0.43 -0.17
    box chair_blue -0.21 0  0.17  -0.17 0.43  0.21
    box chair_blue  0.17 0  0.17   0.21 0.43  0.21
    # backrest
    box chair_blue -0.22 0.48 0.18  0.22 0.95 0.22
  end
end
