material l
  k_emission 1e308
  color 1e308 1 1
end
box l 0 0 0 1 1 1
