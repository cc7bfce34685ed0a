material m
  k_diffrefl 0.5
end
transform
  rotate 1 1 1 1e300
  box m 0 0 0 1 1 1
end
