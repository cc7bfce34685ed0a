# godot zdm2.glb (metres, y up after its node's rotation; about the OBJ's
# Cube units / 10, shifted): the view of zdm2.obj.sc, at 1.4 m above the
# floor in the open-top courtyard of the west half, looking east across
# it at the roofed hall and its arched passage.
camera
  eye -13 0.98 16
  lookat 0.5 -2.42 6
  up 0 1 0
  fov 65
  size 320 240
end
