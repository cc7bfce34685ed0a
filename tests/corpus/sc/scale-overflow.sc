material m
  k_diffrefl 0.5
end
transform
  scale 1e300
  scale 1e300
  box m 0 0 0 1 1 1
end
