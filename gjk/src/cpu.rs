//! CPU-feature versions: the crate's one mechanism for compiling a body
//! twice, for any x86-64 CPU and for AVX2 with FMA, and picking a form.
//!
//! Every form runs the same operations rounded the same way (Rust never
//! fuses a multiply and an add on its own, and `mul_add` rounds once in
//! either form), so the forms give the same answers bit for bit; the AVX2
//! form takes fewer instructions (three-operand forms, wider moves, FMA
//! instructions in place of the software `fma`).
//!
//! A body is written once, as an `#[inline(always)]` function or method;
//! [`cpu_forms!`] writes the compiled forms around it, in one of three
//! shapes:
//! - `dispatch`: a method that picks its form itself, at run time, by
//!   [`has_avx2_fma`] (for out-of-line code reached from either form:
//!   the rare thin-simplex paths);
//! - `pair`: a method in two forms, the caller picking (the subalgorithm's
//!   steps, called from a query already compiled in one form);
//! - `entry`: two free functions around a body generic over
//!   `const AVX2: bool`, so that the body's callees are picked at compile
//!   time (the query's and the compound search's entries).
//!
//! The explicit vector scans (`shape::polytope::scan_avx2`, the f32 scan,
//! the block search's) are intrinsics, not compiled forms of a portable
//! body, and are written as such.

/// Whether this CPU has AVX2 and FMA, what every vector path of the crate
/// needs: detected once, then one load. The standard macro's own cache costs
/// two checks and a frame around its first-call path at every call.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn has_avx2_fma() -> bool {
    use std::sync::atomic::{AtomicU8, Ordering};
    /// 0: not yet known, 1: no, 2: yes.
    static KNOWN: AtomicU8 = AtomicU8::new(0);
    #[cold]
    #[inline(never)]
    fn detect() -> bool {
        let yes = std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma");
        KNOWN.store(if yes { 2 } else { 1 }, Ordering::Relaxed);
        yes
    }
    match KNOWN.load(Ordering::Relaxed) {
        2 => true,
        1 => false,
        _ => detect(),
    }
}

/// Writes the compiled forms of a body (see the [module](self) doc).
///
/// ```text
/// cpu_forms! { dispatch
///     /// doc
///     #[attrs] fn name / name_fma (&mut self, a: A) -> R => name_body
/// }
/// cpu_forms! { pair
///     /// doc
///     #[attrs] pub fn name / name_avx2 (&self, a: A) -> R => name_body
/// }
/// cpu_forms! { entry
///     /// doc
///     #[attrs] pub(super) fn base / avx2 (a: A) -> R => body
/// }
/// ```
macro_rules! cpu_forms {
    (dispatch
        $(#[$attr:meta])* $vis:vis fn $name:ident / $fma:ident
        (&mut self $(, $arg:ident: $ty:ty)*) $(-> $ret:ty)? => $body:ident
    ) => {
        $(#[$attr])*
        $vis fn $name(&mut self $(, $arg: $ty)*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if $crate::cpu::has_avx2_fma() {
                // SAFETY: the CPU has AVX2 and FMA, checked just above.
                return unsafe { self.$fma($($arg),*) };
            }
            self.$body($($arg),*)
        }

        /// The dispatching method's body compiled for AVX2 and FMA.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        fn $fma(&mut self $(, $arg: $ty)*) $(-> $ret)? {
            self.$body($($arg),*)
        }
    };
    (dispatch
        $(#[$attr:meta])* $vis:vis fn $name:ident / $fma:ident
        (&self $(, $arg:ident: $ty:ty)*) $(-> $ret:ty)? => $body:ident
    ) => {
        $(#[$attr])*
        $vis fn $name(&self $(, $arg: $ty)*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if $crate::cpu::has_avx2_fma() {
                // SAFETY: the CPU has AVX2 and FMA, checked just above.
                return unsafe { self.$fma($($arg),*) };
            }
            self.$body($($arg),*)
        }

        /// The dispatching method's body compiled for AVX2 and FMA.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        fn $fma(&self $(, $arg: $ty)*) $(-> $ret)? {
            self.$body($($arg),*)
        }
    };
    (pair
        $(#[$attr:meta])* $vis:vis fn $name:ident / $avx2:ident
        (&mut self $(, $arg:ident: $ty:ty)*) $(-> $ret:ty)? => $body:ident
    ) => {
        $(#[$attr])*
        $vis fn $name(&mut self $(, $arg: $ty)*) $(-> $ret)? {
            self.$body($($arg),*)
        }

        /// The same method compiled for AVX2 and FMA: the same values bit
        /// for bit; callable only on a CPU that has them.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        $(#[$attr])*
        $vis fn $avx2(&mut self $(, $arg: $ty)*) $(-> $ret)? {
            self.$body($($arg),*)
        }
    };
    (pair
        $(#[$attr:meta])* $vis:vis fn $name:ident / $avx2:ident
        (&self $(, $arg:ident: $ty:ty)*) $(-> $ret:ty)? => $body:ident
    ) => {
        $(#[$attr])*
        $vis fn $name(&self $(, $arg: $ty)*) $(-> $ret)? {
            self.$body($($arg),*)
        }

        /// The same method compiled for AVX2 and FMA: the same values bit
        /// for bit; callable only on a CPU that has them.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        $(#[$attr])*
        $vis fn $avx2(&self $(, $arg: $ty)*) $(-> $ret)? {
            self.$body($($arg),*)
        }
    };
    (entry
        $(#[$attr:meta])* $vis:vis fn $base:ident / $avx2:ident
        <$($g:ident: $bound:path),*>
        ($($arg:ident: $ty:ty),*) $(-> $ret:ty)? => $body:ident
    ) => {
        $(#[$attr])*
        $vis fn $base<$($g: $bound),*>($($arg: $ty),*) $(-> $ret)? {
            $body::<false, $($g),*>($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        $(#[$attr])*
        $vis fn $avx2<$($g: $bound),*>($($arg: $ty),*) $(-> $ret)? {
            $body::<true, $($g),*>($($arg),*)
        }
    };
    (entry
        $(#[$attr:meta])* $vis:vis fn $base:ident / $avx2:ident
        ($($arg:ident: $ty:ty),*) $(-> $ret:ty)? => $body:ident
    ) => {
        $(#[$attr])*
        $vis fn $base($($arg: $ty),*) $(-> $ret)? {
            $body::<false>($($arg),*)
        }

        /// The same entry compiled for AVX2 and FMA, its body's callees in
        /// their AVX2 forms; callable only on a CPU that has them.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        $(#[$attr])*
        $vis fn $avx2($($arg: $ty),*) $(-> $ret)? {
            $body::<true>($($arg),*)
        }
    };
}
