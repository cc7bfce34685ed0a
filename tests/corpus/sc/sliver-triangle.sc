material m
  k_diffrefl 0.5
end
polygon m
  vertex 0 0 0
  vertex 1000 0 0
  vertex 1000 0.001 0
end
