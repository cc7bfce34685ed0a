# Sauerbraten zdm2.obj (Cube 2 units): at a player's eye height (14
# units above the floor) in the open-top courtyard of the west half,
# looking east across it at the roofed hall and its arched passage.
camera
  eye -235 94 160
  lookat -100 60 60
  up 0 1 0
  fov 65
  size 320 240
end
