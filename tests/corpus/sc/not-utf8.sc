material m
  k_diffrefl 0.5
end
polygon m
  vertex 0 0 0
  vertex 1 0 0
  vertex 1 ÿ 0
end
