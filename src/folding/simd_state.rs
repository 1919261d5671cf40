//! The vector registers' state after faer's dense kernels: their upper halves cleared, so
//! the scalar code that follows runs at full speed (README, "Speed against error").
//!
//! faer's dense SVD can return with the upper halves of the AVX registers still holding
//! values. Until a `vzeroupper`, every legacy-SSE instruction the rest of the program is
//! compiled to then waits on those halves: the closure residuals after a null-space basis
//! ran seven to eleven times slower on an AVX-512 Xeon.

/// Clears the upper halves of the AVX registers when the CPU has them; nothing otherwise.
#[inline]
pub fn clear_upper_vector_state() {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU supports AVX (checked just above), which is all `vzeroupper`
            // needs; it changes only the registers' upper halves, which hold no value of
            // this (non-AVX) code.
            unsafe { zero_upper() }
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn zero_upper() {
    std::arch::x86_64::_mm256_zeroupper();
}
