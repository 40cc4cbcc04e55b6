// The per-ray value whose relative error --target-error bounds: the twin of ray_stop_value
// (bake/ddgi/trace_batches.h), operation for operation (`precise`: no fused multiply-adds), so the
// device's Welford statistics and the CPU's see the same doubles. With the probe's emitter samples
// (`paired`), the ray's luminance plus its sample's: the combined estimator's terms.
double ray_stop_value(vec3 c, bool paired, vec3 e) {
  precise float lum = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
  precise double x = double(lum);
  if (paired) {
    precise float lum_e = 0.2126 * e.r + 0.7152 * e.g + 0.0722 * e.b;
    x = x + double(lum_e);
  }
  return x;
}
