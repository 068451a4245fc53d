// make_damaged_archives: writes the archives insitu_view_damage.cmake runs insitu-view info and
// verify on (damaged_archives.hpp does the writing and the damage).
//
//   make_damaged_archives OUT
//
//   OUT/clean.cdb     steps 2, 4, 6, 8, 10, views 0 and 1, intact
//   OUT/damaged.cdb   the same, then: step 4 view 0's EXR deleted, step 6 view 1's PNG
//                     truncated, a byte of step 8 view 0's EXR flipped (CRC-32 mismatch), step
//                     10's manifest entry malformed (time null), data.csv unreadable (garbage)
//   OUT/first_corrupt.cdb  steps 2, 4, view 0, a byte of step 2's EXR flipped: the step info
//                          decodes to describe the archive
//   OUT/journal.cdb   steps 2, 4, 6 in manifest.journal, manifest.json corrupt
//   OUT/no_index.cdb  manifest.json corrupt and no journal: nothing left to read
#include <exception>
#include <filesystem>
#include <iostream>

#include "cli/damaged_archives.hpp"

int main(int argc, char** argv) {
    namespace archives = insitu::testing::archives;
    if (argc != 2) {
        std::cerr << "usage: make_damaged_archives OUT\n";
        return 2;
    }
    try {
        const std::filesystem::path out = argv[1];
        std::filesystem::create_directories(out);
        archives::write_small_archive(out / "clean.cdb", {2, 4, 6, 8, 10}, 2);

        const std::filesystem::path damaged = out / "damaged.cdb";
        archives::write_small_archive(damaged, {2, 4, 6, 8, 10}, 2);
        std::filesystem::remove(archives::proxy_file(damaged, 4, 0));
        archives::truncate_half(archives::preview_file(damaged, 6, 1));
        archives::flip_byte(archives::proxy_file(damaged, 8, 0));
        archives::break_step_entry(damaged, 10);
        archives::write_text(damaged / "data.csv", "not,a,cinema,header\n");

        const std::filesystem::path first_corrupt = out / "first_corrupt.cdb";
        archives::write_small_archive(first_corrupt, {2, 4}, 1);
        archives::flip_byte(archives::proxy_file(first_corrupt, 2, 0));

        const std::filesystem::path journal = out / "journal.cdb";
        archives::write_small_archive(journal, {2, 4, 6}, 1);
        archives::move_steps_to_journal(journal);
        archives::corrupt_manifest(journal);

        const std::filesystem::path no_index = out / "no_index.cdb";
        archives::write_small_archive(no_index, {2}, 1);
        archives::corrupt_manifest(no_index);
    } catch (const std::exception& error) {
        std::cerr << "make_damaged_archives: " << error.what() << "\n";
        return 1;
    }
    return 0;
}
