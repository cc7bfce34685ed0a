material m
  k_diffrefl 0.5
end
transform
  scale 1e200
  box m 0 0 0 1 1 1
end
