# godot room.glb (metres): from inside, near the south door, looking
# across the room at the north door and the two far columns of spheres.
camera
  eye 0.8 1.6 4.2
  lookat -0.5 1.4 -2
  up 0 1 0
  fov 60
  size 320 240
end
