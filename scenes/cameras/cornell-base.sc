# A close-up camera for scenes/cornell.sc: the foot of the tall block and
# the floor in front of it, where the block's contact shadow is a sharp
# boundary a regular mesh blurs.  Use with --camera.
camera
  eye 330 160 40
  lookat 360 0 260
  up 0 1 0
  fov 40
  size 480 360
end
