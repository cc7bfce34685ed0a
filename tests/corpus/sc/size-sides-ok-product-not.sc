camera
  eye 0 0 -5
  lookat 0 0 0
  size 65536 65536
end
material m
  k_diffrefl 0.5
end
box m 0 0 0 1 1 1
