//! Reading the caller's pointers: NULL and size checks, each with its
//! error, before anything is dereferenced.

use std::ffi::{CStr, c_char};

use crate::status::Failure;
use crate::types::gjkd_pose;

/// `count` elements at `ptr`, a NULL allowed only when `count` is 0.
///
/// # Safety
/// A non-NULL `ptr` must point to `count` valid elements that stay
/// unchanged for `'a`.
pub unsafe fn slice<'a, T>(ptr: *const T, count: usize, what: &str) -> Result<&'a [T], Failure> {
    if count == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(Failure::null(what));
    }
    check_len::<T>(count, what)?;
    // SAFETY: non-NULL, and the caller promises `count` elements.
    Ok(unsafe { std::slice::from_raw_parts(ptr, count) })
}

/// `count` writable elements at `ptr`, or `None` for NULL.
///
/// # Safety
/// A non-NULL `ptr` must point to `count` writable elements not otherwise
/// referenced for `'a`.
pub unsafe fn slice_mut<'a, T>(
    ptr: *mut T,
    count: usize,
    what: &str,
) -> Result<Option<&'a mut [T]>, Failure> {
    if ptr.is_null() {
        return Ok(None);
    }
    check_len::<T>(count, what)?;
    // SAFETY: non-NULL, and the caller promises `count` elements.
    Ok(Some(unsafe { std::slice::from_raw_parts_mut(ptr, count) }))
}

/// A count whose bytes do not fit the address space is a wrong count, not
/// something to build a slice from.
fn check_len<T>(count: usize, what: &str) -> Result<(), Failure> {
    match count.checked_mul(size_of::<T>().max(1)) {
        Some(bytes) if bytes <= isize::MAX as usize => Ok(()),
        _ => Err(Failure::invalid(format!(
            "{what}: count {count} is larger than any array"
        ))),
    }
}

/// Three doubles at `ptr`.
///
/// # Safety
/// A non-NULL `ptr` must point to three doubles.
pub unsafe fn vec3(ptr: *const f64, what: &str) -> Result<[f64; 3], Failure> {
    if ptr.is_null() {
        return Err(Failure::null(what));
    }
    // SAFETY: non-NULL, and the caller promises three doubles.
    Ok(unsafe { [*ptr, *ptr.add(1), *ptr.add(2)] })
}

/// `*ptr`, required.
///
/// # Safety
/// A non-NULL `ptr` must point to a valid `T`.
pub unsafe fn required<'a, T>(ptr: *const T, what: &str) -> Result<&'a T, Failure> {
    // SAFETY: the caller promises a valid `T` if non-NULL.
    unsafe { ptr.as_ref() }.ok_or_else(|| Failure::null(what))
}

/// Where to write an output, required.
///
/// # Safety
/// A non-NULL `ptr` must be writable.
pub unsafe fn out<'a, T>(ptr: *mut T, what: &str) -> Result<&'a mut T, Failure> {
    // SAFETY: the caller promises a writable `T` if non-NULL.
    unsafe { ptr.as_mut() }.ok_or_else(|| Failure::null(what))
}

/// A NUL-terminated UTF-8 string, or `None` for NULL.
///
/// # Safety
/// A non-NULL `ptr` must point to a NUL-terminated string.
pub unsafe fn opt_str<'a>(ptr: *const c_char, what: &str) -> Result<Option<&'a str>, Failure> {
    if ptr.is_null() {
        return Ok(None);
    }
    // SAFETY: non-NULL and NUL-terminated by the caller's promise.
    let bytes = unsafe { CStr::from_ptr(ptr) };
    bytes
        .to_str()
        .map(Some)
        .map_err(|_| Failure::invalid(format!("{what} is not valid UTF-8")))
}

/// A NUL-terminated UTF-8 string, required.
///
/// # Safety
/// As [`opt_str`].
pub unsafe fn req_str<'a>(ptr: *const c_char, what: &str) -> Result<&'a str, Failure> {
    // SAFETY: forwarded.
    unsafe { opt_str(ptr, what) }?.ok_or_else(|| Failure::null(what))
}

/// A pose that must pass the server's check (finite, within
/// `GJKD_MAX_TRANSLATION`, of unit rotation), named `what` in the error,
/// which carries the server's code for the fault.
pub fn checked_pose(pose: &gjkd_pose, what: &str) -> Result<(), Failure> {
    pose.check()
        .map_err(|(code, why)| Failure::invalid_code(code, format!("{what} {why}")))
}
