camera
  eye 1e12 1e12 1e12
  lookat -1e12 -1e12 -1e12
end
material m
  k_diffrefl 0.5
end
box m -1e12 -1e12 -1e12 1e12 1e12 1e12
