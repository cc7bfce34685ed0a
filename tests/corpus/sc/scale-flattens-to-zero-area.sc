material m
  k_diffrefl 0.5
end
transform
  scale 1 0.000001 1
  polygon m
    vertex 0 0 0
    vertex 1 0 0
    vertex 1 1e-3 0
  end
end
