#pragma once
/// @file published_rom.hpp
/// Published normal ranges of hip motion in living subjects: where the capsule, the ligaments and the muscles
/// end a motion, which a bone-on-bone limit beyond them does not (the soft tissue ends it first). A bony limit
/// is what impinge computes; these are what it is read beside.
///
/// Sources:
/// - American Academy of Orthopaedic Surgeons 1965, "Joint Motion: Method of Measuring and Recording" (the
///   normal values tabulated in Norkin & White, "Measurement of Joint Motion", and Greene & Heckman 1994):
///   flexion 120, extension 30, abduction 45, adduction 30 deg;
/// - Kouyoumdjian et al. 2012, Orthop Traumatol Surg Res 98:17-23 (120 adults, photographic goniometry):
///   rotation with the hip extended (prone) internal 35.2, external 41.8 deg; seated, hip at 90 deg flexion,
///   internal 37.9 and external 40.6 deg (the total 78.5 less the internal).
/// Cadaver studies find that soft tissue ends internal rotation at 0 deg flexion about 80 deg before the bones
/// meet; simulated bony ROM of normal hips (Tannast et al. 2007, J Orthop Res 25:122; Kubiak-Langer et al.
/// 2007, Clin Orthop 458:117) is about 122 deg flexion and 35 deg internal rotation at 90 deg flexion.

#include <string>

namespace impinge {

/// The published normal range of one standard motion (rom.hpp's names).
struct PublishedRange {
  double normal_deg = 0;    ///< the normal passive range in living subjects, deg (NaN: none published, e.g. FADIR)
  const char* source = "";  ///< the citation
};

/// The normal range of `motion` (standard_motions' names: flexion, extension, abduction, adduction,
/// internal_rotation, external_rotation, internal_rotation_90_flexion, external_rotation_90_flexion, fadir);
/// normal_deg NaN and an empty source for any other name. Never throws.
PublishedRange published_normal_range(const std::string& motion);

/// A published simulated bony range of one motion in normal hips: the angle at which the bones of CT or MRI
/// models meet in a computer simulation, without soft tissue, averaged over a cohort: what impinge computes, kept
/// apart from PublishedRange's ranges of living subjects (which the capsule, ligaments and muscles end).
struct BonyRange {
  double bony_deg = 0;     ///< the cohort's mean, deg (NaN: no such range found for the motion)
  const char* frame = "";  ///< the pelvic frame of the published angles: "app" (anterior pelvic plane), or
                           ///< "not stated" where the source does not say
  const char* source = "";  ///< the citation, with the cohort and what exactly was simulated
};

/// The published simulated bony range of `motion` in normal hips (standard_motions' names). Only what could be
/// read in the source itself is given: Audenaert et al. 2012 (Am J Sports Med 40:1329, abstract: 10 healthy
/// controls, 3-D computational simulation): internal rotation on impingement testing 27.9 deg (the flexion-
/// adduction-internal rotation test; impinge's fadir: 90 deg flexion, 10 deg adduction). The Bern studies in the
/// anterior pelvic plane (Tannast et al. 2007, J Orthop Res 25:122; Kubiak-Langer et al. 2007, Clin Orthop
/// 458:117: flexion about 122 deg, internal rotation at 90 deg flexion about 35 deg) are not given here: their
/// tables could not be read to cite their values exactly. bony_deg NaN and an empty source for any other motion.
/// Never throws.
BonyRange published_bony_range(const std::string& motion);

/// Whether soft tissue usually ends `motion` before the bones meet: the bony limit `limit_deg` (NaN: the bones
/// do not meet within the search, RomLimitStatus::free; a motion that is not reached has no limit to judge and
/// is not passed here) lies beyond the published normal range. False where no range is published. Never throws.
bool soft_tissue_first(const std::string& motion, double limit_deg);

}  // namespace impinge
