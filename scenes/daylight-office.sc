# daylight-office.sc -- a side-lit office for the daylight walkthrough.
#
# A room 4 m wide (x), 6 m deep (z, from 0 at the window to -6) and 2.8 m
# high (y up), with one unglazed opening 3 m wide and 1.4 m high in the
# window wall (z = 0), its sill 0.9 m above the floor, and a desk. With y
# up the model's north is -z, so the window faces south. Reflectances:
# ceiling 0.7, walls 0.5, floor 0.2, desk 0.4. Every face of the room
# faces in; outside there is nothing but the sky and its ground.
#
# Units: metres: run it with --units m, for instance
#   radiosity scenes/daylight-office.sc --units m --sky cie-overcast \
#       --daylight-factor --workplane 0.8
# The opening has no glass: multiply the daylight factors by the glazing's
# light transmittance (about 0.7 for double glazing) for a glazed window.

camera
  eye 2 1.5 -5.7
  lookat 2 1.1 0
  up 0 1 0
  fov 70
  size 640 480
end

material ceiling
  color 1 1 1
  k_diffrefl 0.7
end
material wall
  color 1 1 1
  k_diffrefl 0.5
end
material floor
  color 1 1 1
  k_diffrefl 0.2
end
material desk
  color 1 1 1
  k_diffrefl 0.4
end

polygon floor
  vertex 0 0 0
  vertex 4 0 0
  vertex 4 0 -6
  vertex 0 0 -6
end
polygon ceiling
  vertex 0 2.8 0
  vertex 0 2.8 -6
  vertex 4 2.8 -6
  vertex 4 2.8 0
end
# The back wall, and the side walls.
polygon wall
  vertex 0 0 -6
  vertex 4 0 -6
  vertex 4 2.8 -6
  vertex 0 2.8 -6
end
polygon wall
  vertex 0 0 0
  vertex 0 0 -6
  vertex 0 2.8 -6
  vertex 0 2.8 0
end
polygon wall
  vertex 4 0 0
  vertex 4 2.8 0
  vertex 4 2.8 -6
  vertex 4 0 -6
end
# The window wall around the opening (x 0.5 to 3.5, y 0.9 to 2.3):
# below the sill, above the head, and either side.
polygon wall
  vertex 0 0 0
  vertex 0 0.9 0
  vertex 4 0.9 0
  vertex 4 0 0
end
polygon wall
  vertex 0 2.3 0
  vertex 0 2.8 0
  vertex 4 2.8 0
  vertex 4 2.3 0
end
polygon wall
  vertex 0 0.9 0
  vertex 0 2.3 0
  vertex 0.5 2.3 0
  vertex 0.5 0.9 0
end
polygon wall
  vertex 3.5 0.9 0
  vertex 3.5 2.3 0
  vertex 4 2.3 0
  vertex 4 0.9 0
end

# A desk 1.6 x 0.8 m, 0.72 m high, 1.5 m from the window.
box desk 1.2 0 -1.5 2.8 0.72 -2.3
