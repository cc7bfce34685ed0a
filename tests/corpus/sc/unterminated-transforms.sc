transform transform transform
  rotate 0 0 0 90
material m
  k_diffrefl 0.5
end
