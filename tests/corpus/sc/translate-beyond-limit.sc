material m
  k_diffrefl 0.5
end
transform
  translate 9e11 0 0
  translate 9e11 0 0
  box m 0 0 0 1 1 1
end
