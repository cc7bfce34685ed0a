material m
  k_diffrefl 0.5
end
transform
  scale 0.000001
  transform
    scale 0.000001
    box m 0 0 0 1 1 1
  end
end
