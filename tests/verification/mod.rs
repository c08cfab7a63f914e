mod solid;
mod contact;
mod parisch;
