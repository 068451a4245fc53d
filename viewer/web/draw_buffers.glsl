// The colour outputs of a pass that writes values four to a texel: OUTPUTS draw buffers (the
// JS side defines it: 8 where the GPU has that many, else the 4 WebGL2 guarantees), so a pass
// over L intervals takes ceil(L / (4 OUTPUTS)) draws. The JS side prepends it.
layout(location = 0) out vec4 out0;
layout(location = 1) out vec4 out1;
layout(location = 2) out vec4 out2;
layout(location = 3) out vec4 out3;
#if OUTPUTS > 4
layout(location = 4) out vec4 out4;
layout(location = 5) out vec4 out5;
layout(location = 6) out vec4 out6;
layout(location = 7) out vec4 out7;
#endif

void writeOutputs(vec4 outputs[OUTPUTS]) {
  out0 = outputs[0];
  out1 = outputs[1];
  out2 = outputs[2];
  out3 = outputs[3];
#if OUTPUTS > 4
  out4 = outputs[4];
  out5 = outputs[5];
  out6 = outputs[6];
  out7 = outputs[7];
#endif
}
