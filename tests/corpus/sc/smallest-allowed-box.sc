material m
  k_diffrefl 0.5
end
box m 0 0 0 1e-9 1e-9 1e-9
