camera eye 0 0 -5 lookat 0 0 0 up 0 1 0 fov 1e-45 size 64 48 end
material m k_diffrefl 0.5 k_emission 0.1 end
transform translate 1 2 3 rotate 0 1 0 00 scale 2 
polygon m vertex 0 0 0 vertex 1 0 0 vertex 1.5 1 0 vertex 0.5 1.5 0 vertex -0.5 1 0 end
end
