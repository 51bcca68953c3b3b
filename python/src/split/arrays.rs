//! NumPy arrays of the user's MuJoCo read and written in place, through NumPy's
//! `__array_interface__` (the abi3 build cannot use the buffer protocol before Python
//! 3.11; the interface says the same: where the numbers are, their type and their shape).

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A number type an array may hold, by NumPy's type string.
pub(crate) trait Element: Copy {
    /// NumPy's `typestr` of the type (little-endian: the platforms MuJoCo ships for).
    const TYPESTR: &'static str;
}

impl Element for f64 {
    const TYPESTR: &'static str = "<f8";
}

impl Element for f32 {
    const TYPESTR: &'static str = "<f4";
}

impl Element for i32 {
    const TYPESTR: &'static str = "<i4";
}

impl Element for u8 {
    const TYPESTR: &'static str = "|u1";
}

/// A C-contiguous NumPy array of `T`, kept alive (and so the model or data whose memory it
/// views) while this lives. MuJoCo's models and data never move their arrays, so the
/// address read once stays right.
pub(crate) struct Array<T> {
    address: usize,
    len: usize,
    _owner: Py<PyAny>,
    _type: std::marker::PhantomData<T>,
}

impl<T: Element> Array<T> {
    /// `obj` read through its `__array_interface__`: an error names `what` when it is not
    /// a C-contiguous array of `T` (or not writable, with `writable`).
    pub(crate) fn of(obj: &Bound<'_, PyAny>, what: &str, writable: bool) -> PyResult<Self> {
        let wrong = |why: String| PyValueError::new_err(format!("{what}: {why}"));
        let interface = obj
            .getattr("__array_interface__")
            .map_err(|_| wrong("not a NumPy array".into()))?;
        let typestr: String = interface.get_item("typestr")?.extract()?;
        if typestr != T::TYPESTR {
            return Err(wrong(format!("an array of {typestr}, not {}", T::TYPESTR)));
        }
        if !interface.get_item("strides")?.is_none() {
            return Err(wrong("not C-contiguous".into()));
        }
        let shape: Vec<usize> = interface.get_item("shape")?.extract()?;
        let (address, readonly): (usize, bool) = interface.get_item("data")?.extract()?;
        if writable && readonly {
            return Err(wrong("read-only".into()));
        }
        Ok(Array {
            address,
            len: shape.iter().product(),
            _owner: obj.clone().unbind(),
            _type: std::marker::PhantomData,
        })
    }

    /// How many numbers the array holds.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Where the numbers start (to tell two models' arrays apart).
    pub(crate) fn address(&self) -> usize {
        self.address
    }

    /// The numbers.
    ///
    /// # Safety
    /// Nothing writes the array while the slice lives (the caller holds the GIL and runs
    /// no Python code meanwhile, and writes no other view of the same memory).
    pub(crate) unsafe fn slice(&self) -> &[T] {
        if self.len == 0 || self.address == 0 {
            return &[];
        }
        // SAFETY: `len` numbers of `T` at `address`, owned by the array this holds.
        unsafe { std::slice::from_raw_parts(self.address as *const T, self.len) }
    }

    /// The numbers, to write.
    ///
    /// # Safety
    /// As for [`Array::slice`], and no other slice of the same memory lives meanwhile.
    #[allow(clippy::mut_from_ref)]
    pub(crate) unsafe fn slice_mut(&self) -> &mut [T] {
        if self.len == 0 || self.address == 0 {
            return &mut [];
        }
        // SAFETY: as above; checked writable when made.
        unsafe { std::slice::from_raw_parts_mut(self.address as *mut T, self.len) }
    }
}

/// A C-contiguous NumPy array's memory, of any element type, kept alive while this lives.
pub(crate) struct Memory {
    address: usize,
    nbytes: usize,
    /// NumPy's type string of the elements (`<f8`).
    pub(crate) typestr: String,
    /// The array's shape.
    pub(crate) shape: Vec<usize>,
    _owner: Py<PyAny>,
}

impl Memory {
    /// `obj`'s memory through its `__array_interface__`, or `None` when it is not an array.
    pub(crate) fn of(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<Memory>> {
        let Ok(interface) = obj.getattr("__array_interface__") else {
            return Ok(None);
        };
        let wrong = |why: &str| PyValueError::new_err(format!("{what}: {why}"));
        if !interface.get_item("strides")?.is_none() {
            return Err(wrong("not C-contiguous"));
        }
        let typestr: String = interface.get_item("typestr")?.extract()?;
        let size: usize = typestr
            .get(2..)
            .and_then(|n| n.parse().ok())
            .ok_or_else(|| wrong("an element type of no size"))?;
        let shape: Vec<usize> = interface.get_item("shape")?.extract()?;
        let (address, readonly): (usize, bool) = interface.get_item("data")?.extract()?;
        if readonly {
            return Err(wrong("read-only"));
        }
        Ok(Some(Memory {
            address,
            nbytes: size * shape.iter().product::<usize>(),
            typestr,
            shape,
            _owner: obj.clone().unbind(),
        }))
    }

    pub(crate) fn bytes(&self) -> &[u8] {
        if self.nbytes == 0 || self.address == 0 {
            return &[];
        }
        // SAFETY: `nbytes` bytes at `address`, owned by the array this holds; the GIL is
        // held and no Python code runs while the slice lives.
        unsafe { std::slice::from_raw_parts(self.address as *const u8, self.nbytes) }
    }

    pub(crate) fn write(&self, saved: &[u8]) {
        if self.nbytes == 0 || self.address == 0 || saved.len() != self.nbytes {
            return;
        }
        // SAFETY: as in `bytes`, and the array is writable (checked when made); `saved` is
        // the snapshot's own memory, never the model's.
        unsafe { std::slice::from_raw_parts_mut(self.address as *mut u8, self.nbytes) }
            .copy_from_slice(saved);
    }
}
