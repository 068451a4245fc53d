# Tests of the VTK and OpenVDB adaptors and insitu-capture (placeholder)
