# Red Eclipse fortitude.obj (Cube 2 units): at a player's eye height (16
# units above the floor) in the open-top courtyard at the middle of the
# level, looking across it diagonally at its far walls, their dark
# doorways and the arches above.
camera
  eye -200 176 -200
  lookat 200 150 200
  up 0 1 0
  fov 65
  size 320 240
end
