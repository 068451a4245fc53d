// The terms of a frame's last pass (proxy_frame.frag.glsl: lights, occlusion, enhancement, the
// camera they are seen from) as a recipe (/api/recipe) gives them, set the same way whether
// the pass finishes the view's proxies (proxy_renderer.js) or a light field's reconstruction
// (light_field_renderer.js).

export const MAX_LIGHTS = 16;  // kMaxLights (relighting.hpp)

/// Sets the uniforms (`u`: name -> location) of `recipe`'s lights, occlusion and enhancement for
/// `camera` (camera.js) drawn at width x height.
export function setFrameTerms(gl, u, recipe, camera, width, height) {
  gl.uniform3fv(u('uForward'), camera.forward);
  gl.uniform3fv(u('uRight'), camera.right);
  gl.uniform3fv(u('uUp'), camera.up);
  gl.uniform3f(u('uHalfExtent'), camera.halfWidth, camera.halfHeight,
    camera.perspective ? 1 : 0);
  gl.uniform2i(u('uImageSize'), width, height);
  const lighting = recipe.lighting;
  gl.uniform1i(u('uLighting'), lighting ? 1 : 0);
  if (lighting) {
    const lights = new Float32Array(3 * 4 * MAX_LIGHTS);
    lighting.lights.slice(0, MAX_LIGHTS).forEach((light, k) => {
      // A headlight (direction 0) points from the surface toward the camera.
      const headlight = light.direction.every((c) => c === 0);
      const direction = headlight ? camera.forward.map((c) => -c) : light.direction;
      lights.set([...direction, light.shininess, ...light.diffuse, 0, ...light.specular, 0],
        12 * k);
    });
    gl.uniform1f(u('uAmbient'), lighting.ambient);
    gl.uniform1i(u('uLightCount'), Math.min(lighting.lights.length, MAX_LIGHTS));
    gl.uniform4fv(u('uLights'), lights);
  }
  const occlusion = recipe.ambient_occlusion;
  gl.uniform1i(u('uOcclusion'), occlusion ? 1 : 0);
  if (occlusion) {
    gl.uniform1i(u('uOcclusionRadius'), occlusion.radius);
    gl.uniform3f(u('uOcclusionTerms'), occlusion.strength, occlusion.inverse_depth_scale,
      occlusion.inverse_neighbours);
  }
  const enhancement = recipe.enhancement;
  gl.uniform1i(u('uEnhance'), enhancement ? 1 : 0);
  if (enhancement) gl.uniform2f(u('uEnhanceLaw'), enhancement.lambda, enhancement.gamma);
}
