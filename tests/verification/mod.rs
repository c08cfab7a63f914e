mod solid;
mod contact;
