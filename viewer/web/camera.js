// Orbit cameras as the C++ engine defines them (libinsitu/src/core/camera.cpp: Camera::orbit and
// reorbit; the shader's rays are Camera::ray), so that a frame drawn here looks along the same
// rays as `insitu-view render`.
// Angles in degrees; azimuth about +y from +z, elevation above the xz plane (DESIGN.md
// "Conventions"). Vectors are [x, y, z] arrays.

const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const add = (a, b, s = 1) => [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]];

/// A camera from the archive's JSON (Camera::to_json: projection, size, orbit_center,
/// orbit_radius, fov for perspective) seen from other orbit angles, as Camera::reorbit.
export function reorbit(stored, azimuthDeg, elevationDeg) {
  return orbitCamera({
    projection: stored.projection,
    width: stored.size[0],
    height: stored.size[1],
    fovDeg: stored.fov,
    center: stored.orbit_center,
    radius: stored.orbit_radius,
  }, azimuthDeg, elevationDeg);
}

/// Camera::orbit around the sphere (center, radius) that the orbit frames.
export function orbitCamera(view, azimuthDeg, elevationDeg) {
  const az = azimuthDeg * Math.PI / 180;
  const el = elevationDeg * Math.PI / 180;
  const towards = [Math.sin(az) * Math.cos(el), Math.sin(el), Math.cos(az) * Math.cos(el)];
  const forward = towards.map((c) => -c);
  // right = normalize(forward x +y), written out so that it stays defined at the poles.
  const right = [Math.cos(az), 0, -Math.sin(az)];
  const up = cross(right, forward);
  const radius = Math.max(view.radius, 1e-6);
  const aspect = view.width / view.height;
  const camera = {
    perspective: view.projection === 'perspective',
    width: view.width,
    height: view.height,
    forward,
    right,
    up,
  };
  if (!camera.perspective) {
    camera.halfHeight = aspect >= 1 ? radius : radius / aspect;
    camera.halfWidth = camera.halfHeight * aspect;
    camera.position = add(view.center, towards, radius);
  } else {
    camera.halfHeight = Math.tan(0.5 * view.fovDeg * Math.PI / 180);
    camera.halfWidth = camera.halfHeight * aspect;
    const halfAngle = Math.atan(Math.min(camera.halfHeight, camera.halfWidth));
    camera.position = add(view.center, towards, radius / Math.sin(halfAngle));
  }
  return camera;
}

/// The stored camera (Camera::to_json) in the shape orbitCamera returns, exactly as stored.
export function storedCamera(json) {
  return {
    perspective: json.projection === 'perspective',
    width: json.size[0],
    height: json.size[1],
    forward: json.forward,
    right: json.right,
    up: json.up,
    halfWidth: json.half_width,
    halfHeight: json.half_height,
    position: json.position,
  };
}

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const length = (a) => Math.sqrt(dot(a, a));

/// The rigid map from `from`'s local coordinates (right, up, forward offsets from its position)
/// to `to`'s, as three rows [r0, r1, r2, t] (seed 000 Eq. 4, M_new M_orig^-1), as view
/// synthesis's local_map: in double, entries within rounding of 0 or +-1 snapped, so that an
/// unchanged camera maps every point onto itself.
export function localMap(from, to) {
  const fromAxes = [from.right, from.up, from.forward];
  const toAxes = [to.right, to.up, to.forward];
  const scale = 1 + length(from.position) + length(to.position);
  const offset = add(from.position, to.position, -1);
  return toAxes.map((axis) => {
    const row = fromAxes.map((f) => {
      const r = dot(axis, f);
      return Math.abs(r - Math.round(r)) < 1e-12 ? Math.round(r) : r;
    });
    const t = dot(offset, axis);
    return [...row, Math.abs(t) < 1e-12 * scale ? 0 : t];
  });
}

/// The sphere bounding the field (the stored camera's orbit sphere, Camera::to_json) in the
/// target's local coordinates, radius padded by float rounding: [x, y, z, radius].
export function boundingSphereIn(stored, target) {
  const offset = add(stored.orbit_center, target.position, -1);
  return [dot(offset, target.right), dot(offset, target.up), dot(offset, target.forward),
    stored.orbit_radius * (1 + 1e-5)];
}
