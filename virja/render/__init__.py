"""Drawing the band with moderngl: shaders, meshes, camera, hosts, video."""
