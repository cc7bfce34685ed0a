# xeogl vianney_house_2/scene.gltf (the file's units, up +z, floor at
# z 0.89): at eye height (10 units above the floor) in the south half of
# the glazed hall, looking north (+y) at the plastered west wall, the
# roofed gallery and its spiral stair; the top of the picture is the
# open sky over the hall.
camera
  eye 30 -55 11
  lookat -20 60 7
  up 0 0 1
  fov 65
  size 320 240
end
