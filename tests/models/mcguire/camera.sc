# A camera for McGuire's Cornell boxes (CornellBox-*.obj): the boxes are
# open towards +z, so the eye stands on that side and looks in along -z.
# Use with --camera.
camera
  eye 0 1 3.9
  lookat 0 1 0
  up 0 1 0
  fov 39
  size 480 360
end
