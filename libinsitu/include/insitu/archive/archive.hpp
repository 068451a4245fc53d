#pragma once
// The timestep proxy archive (DESIGN.md "Archive"): a directory that is at once a Cinema Spec D
// database (data.csv + PNG previews), libinsitu's manifest.json, and one multi-part OpenEXR file
// per timestep and view. Writes are crash-safe (temp file, fsync, rename); the indexes only ever
// name complete files.
//
// Layout of ARCHIVE/:
//   data.csv                         time,step,view,phi,theta,proxy_exr,volume_zfp,FILE
//                                    (FILE last: PNG; volume_zfp: the first block's stream of
//                                    the step's compressed field of the view's field, empty
//                                    without one. data.csv written before volume_zfp, without
//                                    the column, still reads; the next writer adds it)
//   manifest.json                    schema_version, producer, configuration, steps[...]
//   manifest.journal                 steps since manifest.json was compacted, one JSON a line
//   .lock                            flock()ed by the one writer, holding its pid
//   proxies/step000010_view0.exr     multi-part EXR, self-describing parts and channels
//   proxies/step000010_lightfield1.exr  a light field (seed 001) of field 1 of "fields": a part
//                                    per camera, so a reader decodes only the cameras it needs
//   previews/step000010_view0.png    ground-truth rendering of the configured transfer function
//   volumes/step000010_field0.zfp    the compressed field of field 0 of "fields": a ZFP stream
//                                    (src/representation/volume/volume_entries.hpp), with NaN/Inf a
//                                    .mask beside it, "_block<b>" per block of a distributed run
//
// EXR parts (channel names start with the part name; libinsitu/src/archive/archive_format.hpp):
//   depth (depth.layer0..), attenuation (attenuation.a00.., .zmean00.., .tau00.., .zentry00..,
//   .reentries, .reentered),
//   train0.. (train0.R/G/B/A), model (model.table: the colour model of seed 000 §6.2, one row
//   of (4 L + 3) floats per cluster, with libinsitu.model_{intervals, clusters, layout,
//   training_transfer_functions}), multi.depth (multi.depth.layer0..), multi.distortion
//   (multi.distortion.layer0..), multi.attenuation (multi.attenuation.a00.., ...).
// Depth, distortion and the model are always FLOAT; the rest HALF or FLOAT by "precision" (a
// budget that chooses it sets it per step and field: ViewRecord::precision). The
// model is stored whenever the Instrument fitted one (training transfer functions configured);
// the training renderings it was fitted on only with keep_training_images. Every part
// carries the header attributes libinsitu.{schema_version, step, time, field, view, view_config,
// perspective, camera, isovalues, intervals, transfer_function, training_transfer_functions}
// (+ distortion_tilt on multi.* parts, training_transfer_function on train<k>); JSON text in
// string attributes, doubles exact.
//
// Light-field parts camera<k> (k: the camera's index in the rig): camera<k>.R/G/B/A (or
// camera<k>.segment<s>.R/G/B/A and .depth per segment when the rays are split), camera<k>.depth
// (first hit, as a secant fraction: 16-bit HALF or seed 001's 8 bits, +inf / code 255 = no hit),
// camera<k>.a00.. and .zmean00.. (the attenuation light field). Every part carries
// libinsitu.{schema_version, step, time, field, light_field, isovalues, intervals,
// transfer_function, camera_index, camera, depth_encoding}, the first part also libinsitu.rig.
// The manifest lists them per step under "light_fields" (field, file, bytes, crc32, cameras,
// map_size), a key steps without light fields do not have.
//
// One writer per archive at a time, enforced: a second ArchiveWriter (any process) is refused
// while the first holds ARCHIVE/.lock; readers take no lock. A writer removes temp files
// (".tmp-*") that killed runs left behind when it opens the archive, and folds the journal into
// manifest.json. A step costs O(1) in the length of the run: its rows are appended to data.csv
// and its entry to manifest.journal (src/archive/manifest.hpp).
//
// This header includes both sides: archive_writer.hpp (ArchiveWriter, StepRecord) and
// archive_reader.hpp (ArchiveReader).
#include "insitu/archive/archive_reader.hpp"
#include "insitu/archive/archive_writer.hpp"
