# Sauerbraten pandora.obj (Cube 2 units): at a player's eye height (18
# units) on the floor of the small open-top courtyard near the middle of
# the level, looking north at its stairs and the roofed galleries.
camera
  eye -100 226 -10
  lookat -100 200 120
  up 0 1 0
  fov 65
  size 320 240
end
