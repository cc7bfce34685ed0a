material m
  k_diffrefl 0.5
end
polygon m
  vertex 1e30 0 0
  vertex 0 1e30 0
  vertex 0 0 1e30
end
